def e2c(*a, **k): raise NotImplementedError
def c2e(*a, **k): raise NotImplementedError
def e2p(*a, **k): raise NotImplementedError
def c2p(*a, **k): raise NotImplementedError
