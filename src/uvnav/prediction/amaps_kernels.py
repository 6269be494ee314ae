"""Compiled AMAPS sweep update (thesis Ch. 4, Fig. 4.4) — the same arithmetic as the numpy path.

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 4, §4.2 (AMAPS).  The update rule itself is the one documented in
:mod:`uvnav.prediction.amaps`; this module only runs it as one compiled loop over the squares the
beams touch, with numba (extra ``fast``), because the numpy path spends most of a decision in the
overhead of its ~30 array calls per sweep rather than in the arithmetic.

Results are *identical* to the numpy path (checked by ``tests/prediction/test_prediction_amaps.py``
against a reference copy of the original implementation):

* every sample position is computed with the same operations in the same order
  (``floor(((o - x0) + s * d) / h)`` for free space, ``floor(((o + (rho + s) * d) - x0) / h)`` for
  returns), in float64 without fast-math, so no fused multiply-add changes a rounding;
* numpy's buffered fancy updates (a square touched twice in one sweep reads the same old value
  and writes the same new one) are reproduced by gathering all new values first and writing them
  afterwards; labels are written in beam order, the last write winning as in numpy;
* counts stay float32 (``max(c - w, 0)`` and ``c + w`` in float32 with the float32 weights).

numba is imported lazily by :func:`load_kernel`; without it the grid keeps the numpy path.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

_KERNEL: tuple[Callable[..., None], Callable[..., tuple[Any, Any, Any]]] | None = None
_TRIED = False


def _sweep(
    stored: Any,
    labels: Any,
    ox: float,
    oy: float,
    x0: float,
    y0: float,
    h: float,
    dx: Any,
    dy: Any,
    rr: Any,
    ids: Any,
    free_w: Any,
    hit_w: Any,
    fs: float,
    free_range: float,
    do_free: bool,
    n_d: int,
    step: float,
    row_lo: Any,
    row_hi: Any,
) -> None:  # pragma: no cover - compiled by numba; the numpy path is the reference
    """One sweep on the flat ``stored`` (float32) and ``labels`` (int16) arrays of an
    ``ny x nx`` grid (see the module docstring for the arithmetic).

    ``row_lo``/``row_hi`` (ny,) hold, per row, the lowest and highest column ever marked covered:
    only those squares can hold a positive count (free space only lowers counts, decay only
    scales them), so :func:`_scan_near` need not look elsewhere."""
    ny, nx = stored.shape
    flat_s = stored.reshape(-1)
    flat_l = labels.reshape(-1)
    b = rr.shape[0]
    ax = ox - x0
    ay = oy - y0
    if do_free and b > 0:
        rmax = rr[0]
        for i in range(1, b):
            if rr[i] > rmax:
                rmax = rr[i]
        n_s = int(np.ceil(min(rmax, free_range) / fs)) + 1
        idx = np.empty(b * n_s, dtype=np.intp)
        m = 0
        for i in range(b):
            lim = rr[i] - h if ids[i] >= 0 else rr[i]
            if lim > free_range:
                lim = free_range
            for k in range(n_s):
                s = k * fs
                if not (s < lim):
                    break
                c = np.floor((ax + s * dx[i]) / h)
                r = np.floor((ay + s * dy[i]) / h)
                if c >= 0 and c < nx and r >= 0 and r < ny:
                    idx[m] = int(r) * nx + int(c)
                    m += 1
        new = np.empty(m, dtype=np.float32)
        for j in range(m):
            v = flat_s[idx[j]] - free_w
            new[j] = v if v > 0 else np.float32(0.0)
        for j in range(m):
            flat_s[idx[j]] = new[j]
    if n_d > 0:
        idx = np.empty(b * n_d, dtype=np.intp)
        lab = np.empty(b * n_d, dtype=np.int16)
        m = 0
        for i in range(b):
            if ids[i] < 0:
                continue
            for k in range(n_d):
                t = rr[i] + k * step
                c = np.floor(((ox + t * dx[i]) - x0) / h)
                r = np.floor(((oy + t * dy[i]) - y0) / h)
                if c >= 0 and c < nx and r >= 0 and r < ny:
                    ir = int(r)
                    ic = int(c)
                    idx[m] = ir * nx + ic
                    lab[m] = ids[i]
                    m += 1
                    if ic < row_lo[ir]:
                        row_lo[ir] = ic
                    if ic > row_hi[ir]:
                        row_hi[ir] = ic
        new = np.empty(m, dtype=np.float32)
        for j in range(m):
            new[j] = flat_s[idx[j]] + hit_w
        for j in range(m):
            flat_s[idx[j]] = new[j]
            flat_l[idx[j]] = lab[j]


def _scan_near(
    stored: Any,
    labels: Any,
    row_lo: Any,
    row_hi: Any,
    r0: int,
    r1: int,
    c0: int,
    c1: int,
    level: Any,
    x0: float,
    y0: float,
    h: float,
    px: float,
    py: float,
    radius: float,
) -> tuple[Any, Any, Any]:  # pragma: no cover - compiled by numba
    """:meth:`AmapsGrid.covered` in one pass: the squares of ``stored[r0:r1, c0:c1]`` with a count
    ``>= level`` whose centres lie within ``radius`` of ``(px, py)``, row-major, as ``(centres
    (m, 2), labels (m,), distances (m,))`` — the centre ``x0 + (c + 0.5) h`` and the distance
    ``hypot`` computed as the numpy path does, so the results are identical.  Per row only the
    columns between ``row_lo`` and ``row_hi`` (ever marked covered, see :func:`_sweep`) are read.
    """
    n = 0
    for r in range(r0, r1):
        n += max(min(c1, row_hi[r] + 1) - max(c0, row_lo[r]), 0)
    centres = np.empty((n, 2))
    labs = np.empty(n, dtype=np.intp)
    dists = np.empty(n)
    m = 0
    for r in range(r0, r1):
        cy = y0 + (r + 0.5) * h
        for c in range(max(c0, row_lo[r]), min(c1, row_hi[r] + 1)):
            if stored[r, c] >= level:
                cx = x0 + (c + 0.5) * h
                d = math.hypot(cx - px, cy - py)
                if d <= radius:
                    centres[m, 0] = cx
                    centres[m, 1] = cy
                    labs[m] = labels[r, c]
                    dists[m] = d
                    m += 1
    return centres[:m], labs[:m], dists[:m]


def load_kernel() -> tuple[Callable[..., None], Callable[..., tuple[Any, Any, Any]]] | None:
    """The compiled sweep update and near-squares scan, or ``None`` when numba
    (extra ``fast``) is not installed."""
    global _KERNEL, _TRIED
    if not _TRIED:
        _TRIED = True
        try:
            import numba
        except ImportError:
            return None
        jit = numba.njit(cache=True, nogil=True)
        _KERNEL = (jit(_sweep), jit(_scan_near))
    return _KERNEL
