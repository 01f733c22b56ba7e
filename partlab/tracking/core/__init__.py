"""Machinery every tracker shares: boxes, colour histograms (YCbCr and hue), integral
histograms and compiled kernels, resampling, the background model and skin colour."""
