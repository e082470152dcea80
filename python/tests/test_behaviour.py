"""What Python users expect: no leak over many calls, the GIL released, Ctrl-C stops a
long call."""

import gc
import signal
import threading
import time

import numpy as np
import psutil
import pytest

import mirrorball as mb


def rss():
    gc.collect()
    return psutil.Process().memory_info().rss


def test_no_leak_over_1000_calls(smooth, tmp):
    plan = mb.Remap(smooth.shape, dst="cube", size=32, layout="separate")
    out = np.empty((6, 32, 32, 3), np.float32)
    mb.write(tmp / "a.exr", smooth)
    bad = smooth.astype(np.float64)

    def calls():
        mb.convert(smooth, dst="cube", size=32)
        plan.apply(smooth, out=out)
        plan.apply(smooth)
        mb.read(tmp / "a.exr")
        with pytest.raises(TypeError):
            mb.convert(bad)
        with pytest.raises(FileNotFoundError):
            mb.read(tmp / "none.exr")

    for _ in range(100):
        calls()
    before = rss()
    for _ in range(1000):
        calls()
    grown = rss() - before
    # Each round allocates about 1.3 MB and frees it; a leak of even 1 KB a call shows.
    assert grown < 4 << 20, f"RSS grew {grown / 2**20:.1f} MiB over 1000 rounds"


def test_the_gil_is_released(smooth):
    big = np.ones((1024, 2048, 3), np.float32)
    ticks = []
    done = threading.Event()

    def work():
        for _ in range(6):
            mb.convert(big, dst="cube", size=512)
        done.set()

    t = threading.Thread(target=work)
    t0 = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    t.join()
    total = time.perf_counter() - t0
    # The main thread ran all along: no gap of a whole conversion between its ticks (a
    # held GIL would stop it for all six; a loaded machine may pause it a little).
    gaps = np.diff(ticks)
    assert len(ticks) > 20 and gaps.max() < total / 12, (len(ticks), gaps.max(), total)


def test_ctrl_c_interrupts_a_long_call():
    big = np.ones((2048, 4096, 3), np.float32)
    t0 = time.perf_counter()
    mb.convert(big[:512, :1024], dst="cube", size=256)
    signal.setitimer(signal.ITIMER_REAL, 0.3)

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGALRM, interrupt)
    try:
        t0 = time.perf_counter()
        with pytest.raises(KeyboardInterrupt):
            for _ in range(100):
                mb.convert(big, dst="cube", size=2048, max_samples=16)
        elapsed = time.perf_counter() - t0
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    # One band of rows at most after the signal, not the rest of the call.
    assert elapsed < 3.0, elapsed


class Tensorish:
    """Another library's CPU array as mirrorball meets it: only the DLPack protocol (what
    torch tensors and JAX arrays offer), over a numpy array's memory."""

    def __init__(self, a, device=(1, 0)):
        self.a = a
        self.device = device

    def __dlpack__(self, **kwargs):
        if self.device[0] != 1:
            # What numpy meets in a GPU tensor's capsule.
            raise BufferError("Unsupported device in DLTensor.")
        return self.a.__dlpack__(**kwargs)

    def __dlpack_device__(self):
        return self.device


def test_arrays_come_through_dlpack(smooth):
    cube = mb.convert(smooth, dst="cube", size=16, layout="separate")
    assert np.array_equal(mb.convert(Tensorish(smooth), dst="cube", size=16, layout="separate"), cube)
    plan = mb.Remap(smooth.shape, dst="cube", size=16, layout="separate")
    assert np.array_equal(plan.apply(Tensorish(smooth)), plan.apply(smooth))
    codes = (smooth.clip(0, 1) * 255).astype(np.uint8)
    assert np.array_equal(plan.apply(Tensorish(codes)), plan.apply(codes))
    assert np.array_equal(mb.sh9(Tensorish(smooth)), mb.sh9(smooth))
    # A tensor on a GPU (DLPack's device 2, CUDA) is refused, naming the argument.
    with pytest.raises(TypeError, match="array: read through DLPack"):
        mb.convert(Tensorish(smooth, device=(2, 0)), dst="cube", size=16)
    # Neither numpy nor DLPack: a TypeError naming what is needed.
    with pytest.raises(TypeError, match="__dlpack__"):
        mb.convert([[1.0, 2.0, 3.0]], dst="cube", size=16)
