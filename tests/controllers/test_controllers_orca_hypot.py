"""hypot_versus_py: every comparison with the limit comes out as pyhypot's."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvnav.controllers.orca_kernels import hypot_versus_py
from uvnav.geometry.small import pyhypot


def _sides(h: float, limit: float) -> tuple[bool, bool, bool, bool]:
    return h >= limit, h <= limit, h > limit, h < limit


@pytest.mark.parametrize("limit", [1e-6, 0.25, 3.0, 0.0, 1e-200, 1e200])
def test_comparisons_match_pyhypot(limit: float) -> None:
    rng = np.random.default_rng(7)
    cases = [(0.0, 0.0), (math.nan, 1.0), (math.inf, 0.0), (1e300, 1e300), (-limit, 0.0)]
    for _ in range(3000):
        angle = rng.uniform(0.0, 2.0 * math.pi)
        # around the limit: a relative offset from 1e-17 to 1e-6, either side, and far away
        scale = limit * (1.0 + rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-17.0, -6.0))
        if rng.random() < 0.2:
            scale = limit * 10.0 ** rng.uniform(-3.0, 3.0)
        cases.append((scale * math.cos(angle), scale * math.sin(angle)))
    for x, y in cases:
        got, want = hypot_versus_py(x, y, limit), pyhypot(x, y)
        assert _sides(got, limit) == _sides(want, limit), (x, y, limit)


def test_near_the_limit_it_is_pyhypot() -> None:
    x, y = 0.6e-6, 0.8e-6 * (1.0 + 1e-12)
    assert hypot_versus_py(x, y, 1e-6) == pyhypot(x, y)
    assert hypot_versus_py(3.0, 4.0, 1.0) == math.inf
    assert hypot_versus_py(0.3, 0.4, 1.0) == 0.0
