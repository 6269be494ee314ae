"""Planar angles: wrapping, signed angles between vectors, unit headings.

Conventions: angles in [rad], counter-clockwise positive, wrapped to the half-open interval
(-pi, pi] so that a signed angle of exactly pi is reported as +pi (the thesis's f(.) in eq. (2.14)
assigns beta = pi to the positive branch).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def wrap_to_pi(angle: ArrayLike) -> FloatArray:
    """Wrap ``angle`` [rad] to (-pi, pi]; vectorised, NaN-free for finite input."""
    a = np.asarray(angle, dtype=float)
    wrapped = np.pi - np.mod(np.pi - a, 2.0 * np.pi)
    wrapped = np.where(wrapped <= -np.pi, np.pi, wrapped)
    return np.asarray(np.where((a > -np.pi) & (a <= np.pi), a, wrapped))


def wrap_scalar(angle: float) -> float:
    """Scalar :func:`wrap_to_pi` returning a Python float [rad]."""
    a = float(angle)
    if -math.pi < a <= math.pi:
        return a
    w = math.pi - (math.pi - a) % (2.0 * math.pi)
    return w if w > -math.pi else math.pi


def heading_vector(theta: ArrayLike) -> FloatArray:
    """Unit vector(s) ``[cos theta, sin theta]`` for heading(s) ``theta`` [rad]; shape (..., 2)."""
    t = np.asarray(theta, dtype=float)
    return np.stack([np.cos(t), np.sin(t)], axis=-1)


def vector_angle(vec: ArrayLike) -> FloatArray:
    """Angle [rad] of vector(s) ``vec`` (..., 2) from the +x axis, in (-pi, pi]."""
    v = np.asarray(vec, dtype=float)
    return wrap_to_pi(np.arctan2(v[..., 1], v[..., 0]))


def signed_angle(from_vec: ArrayLike, to_vec: ArrayLike) -> FloatArray:
    """Angle [rad] that rotates ``from_vec`` onto ``to_vec``, counter-clockwise positive, in
    (-pi, pi].

    Zero-length vectors give 0 (never NaN).
    """
    a = np.asarray(from_vec, dtype=float)
    b = np.asarray(to_vec, dtype=float)
    cross = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    dot = a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]
    return wrap_to_pi(np.arctan2(cross, dot))
