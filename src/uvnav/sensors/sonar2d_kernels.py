"""Compiled pair search of the Fig. 4.2(b) narrow-opening detector (thesis Ch. 4 §4.2).

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 4, §4.2, Fig. 4.2(b).  :func:`uvnav.sensors.sonar2d.
close_narrow_openings` looks for pairs of returns closer than the vehicle's width with something
to close between them; its numpy form builds several (n x n) matrices per sweep.  This module finds
the same pairs, in the same (row-major) order, with one compiled loop (numba, extra ``fast``):

* the distance is ``hypot(dx, dy)`` of the same differences (the C library's ``hypot``, as
  ``numpy.hypot`` uses), and a pair is skipped early only when ``|dx|`` or ``|dy|`` alone already
  reaches the width (``hypot`` is never below either), so the ``< width`` test decides alike;
* "a return deeper than both lips" is the running maximum of the ranges strictly between the two
  returns, as the numpy path's ``maximum.accumulate``.

``tests/sensors/test_sensors_sonar2d.py`` checks both paths give identical clipped ranges.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

_KERNEL: Callable[..., tuple[Any, Any]] | None = None
_TRIED = False


def _pairs(
    px: Any, py: Any, rr: Any, idx: Any, width: float
) -> tuple[Any, Any]:  # pragma: no cover - compiled by numba
    """Index pairs (i < j, row-major) of returns closer than ``width`` with a missing beam or a
    deeper return between them, at least two beams apart."""
    n = px.shape[0]
    out_i = np.empty(n * (n - 1) // 2, dtype=np.intp)
    out_j = np.empty(n * (n - 1) // 2, dtype=np.intp)
    m = 0
    for i in range(n):
        running = -np.inf  # max rr[i+1 .. j-1]
        for j in range(i + 1, n):
            dx = px[i] - px[j]
            dy = py[i] - py[j]
            if abs(dx) < width and abs(dy) < width and math.hypot(dx, dy) < width:
                gap = idx[j] - idx[i]
                if gap >= 2:
                    missing = gap > (j - i)
                    deeper = (j - i >= 2) and running > max(rr[i], rr[j])
                    if missing or deeper:
                        out_i[m] = i
                        out_j[m] = j
                        m += 1
            if rr[j] > running:
                running = rr[j]
    return out_i[:m], out_j[:m]


def load_pairs_kernel() -> Callable[..., tuple[Any, Any]] | None:
    """The compiled pair search, or ``None`` when numba (extra ``fast``) is not installed."""
    global _KERNEL, _TRIED
    if not _TRIED:
        _TRIED = True
        try:
            import numba
        except ImportError:
            return None
        _KERNEL = numba.njit(cache=True, nogil=True)(_pairs)
    return _KERNEL
