"""LazyYcc converts only the tiles asked for, to exactly OpenCV's values."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from partlab.tracking.core import kernels
from partlab.tracking.core.lazy_ycc import LazyYcc, as_array, cover


def test_lazy_ycc_matches_opencv_where_converted():
    rng = np.random.default_rng(0)
    frame = rng.integers(0, 256, (70, 100, 3), dtype=np.uint8)
    frame[0, :8] = [(0, 0, 255), (255, 0, 0), (0, 255, 0), (255, 255, 255), (0, 0, 0), (255, 0, 255),
                    (0, 255, 255), (255, 255, 0)]  # saturated colours: Cr and Cb at their extremes
    expect = cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb)
    ycc = LazyYcc(frame)
    got = ycc.cover(30, 10, 40, 20)
    assert np.array_equal(got[10:20, 30:40], expect[10:20, 30:40])
    assert np.array_equal(cover(ycc, 0, 0, 8, 1)[0, :8], expect[0, :8])
    if kernels.HAVE_NUMBA:  # the first region spans two 32 x 32 tiles, the second lies in one of them
        assert ycc.done is not None and ycc.done.sum() == 2 and ycc.done[0, 0] and ycc.done[0, 1]
    assert np.array_equal(as_array(ycc), expect)
    ycc.load(np.ascontiguousarray(frame[::-1]))  # next frame reuses the buffer
    assert np.array_equal(ycc.cover(90, 60, 100, 70)[60:70, 90:100], expect[::-1][60:70, 90:100])
    with pytest.raises(ValueError, match="uint8"):
        ycc.load(frame.astype(np.float32))
