"""Vectorised point-to-segment distances (exact) for many independent pairs at once."""

from __future__ import annotations

import numpy as np

from uvnav.geometry.angles import FloatArray

_EPS = 1e-12


def points_to_segments(points: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Distance [m] from each point to the matching segment ``a``-``b``; (N, 2) arrays -> (N,)."""
    d = b - a
    len2 = np.maximum(np.einsum("ij,ij->i", d, d), _EPS)
    t = np.clip(np.einsum("ij,ij->i", points - a, d) / len2, 0.0, 1.0)
    diff = a + t[:, None] * d - points
    return np.sqrt(np.einsum("ij,ij->i", diff, diff))
