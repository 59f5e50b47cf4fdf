"""Error metrics of an image against a reference, computed by the same code as ``strata compare``
(H x W x 3 arrays, any float dtype)."""

import numpy as np

from . import _strata


def _pair(img, ref):
    a = np.ascontiguousarray(img, dtype="<f4")
    b = np.ascontiguousarray(ref, dtype="<f4")
    if a.shape != b.shape or a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"expected two H x W x 3 images of one shape, got {a.shape} and {b.shape}")
    return a.tobytes(), b.tobytes()


def mse(img, ref):
    """Mean squared error over pixels and channels."""
    return _strata.mse(*_pair(img, ref))


def rmse(img, ref):
    """Root mean squared error."""
    return mse(img, ref) ** 0.5


def relmse(img, ref):
    """Relative MSE in pbrt's form, mean of (img - ref)^2 / (ref + 0.01)^2, as ``strata compare``."""
    return _strata.relmse(*_pair(img, ref))


def flip(img, ref, return_map=False):
    """Mean FLIP (Andersson et al. 2020, LDR: both linear images go to 8-bit sRGB first), as the
    FLIP column of ``strata compare``; with ``return_map=True`` also the H x W per-pixel map."""
    a, b = _pair(img, ref)
    h, w = np.shape(img)[:2]
    mean, m = _strata.flip(a, b, w, h)
    if return_map:
        return mean, np.frombuffer(m, dtype="<f4").reshape(h, w)
    return mean
