// cube-container tests (KTX2, DDS)
