// flat-image tests (EXR, HDR, PNG, JPEG)
