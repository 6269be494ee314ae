"""AMAPS count grid (thesis Ch. 4, Fig. 4.4): counts, forgetting, threshold, r_imin, memory."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.prediction.amaps import AmapsConfig, AmapsGrid


def grid(**kw: float) -> AmapsGrid:
    return AmapsGrid.covering(np.array([0.0, 0.0]), np.array([10.0, 10.0]), AmapsConfig(**kw))


@settings(max_examples=30, deadline=None)
@given(
    r=st.floats(0.5, 4.0),
    a=st.floats(-np.pi, np.pi),
    n=st.integers(1, 6),
)
def test_repeated_returns_count_once_per_sweep(r: float, a: float, n: int) -> None:
    g = grid(decay=1.0, free_weight=0.0, hit_depth=0.0)
    o = np.array([5.0, 5.0])
    for _ in range(n):
        # three beams hitting the same point: still one count per sweep
        g.update(o, np.full(3, a), np.full(3, r), np.array([2, 2, 2]))
    p = o + r * np.array([np.cos(a), np.sin(a)])
    c, row, ok = g.cell_of(p[None])
    assert ok[0]
    assert g.counts[row[0], c[0]] == n
    assert float(g.counts.sum()) == n
    assert g.labels[row[0], c[0]] == 2
    d, centre, lab = g.nearest(o, 5.0)
    assert lab == 2 and centre is not None
    assert abs(d - r) <= g.config.cell  # r_imin is the square's centre, within one square


def test_forgetting_and_free_space_clear_old_squares() -> None:
    g = grid(decay=0.9, threshold=0.5, free_weight=0.0, hit_depth=0.0)
    o = np.array([5.0, 5.0])
    g.update(o, np.array([0.0]), np.array([2.0]), np.array([0]))
    assert np.isfinite(g.nearest(o, 5.0)[0])
    for _ in range(7):  # 0.9^7 < 0.5: forgotten
        g.update(o, np.array([np.pi]), np.array([np.nan]), np.array([-1]))
    assert not np.isfinite(g.nearest(o, 5.0)[0])
    # free-space evidence: a beam passing through an occupied square lowers it
    g2 = grid(decay=1.0, free_weight=1.0, hit_depth=0.0)
    g2.update(o, np.array([0.0]), np.array([1.0]), np.array([0]))
    g2.update(o, np.array([0.0]), np.array([3.0]), np.array([-1]))
    assert not np.isfinite(g2.nearest(o, 5.0)[0])


def test_nearest_passing_the_threshold_wins_and_memory_is_fixed() -> None:
    g = grid(decay=1.0, threshold=2.0, free_weight=0.0, hit_depth=0.0)
    o = np.array([5.0, 5.0])
    size = g.nbytes
    g.update(o, np.array([0.0, np.pi / 2]), np.array([1.0, 2.0]), np.array([0, 1]))
    assert not np.isfinite(g.nearest(o, 5.0)[0])  # one count < threshold 2
    g.update(o, np.array([np.pi / 2]), np.array([2.0]), np.array([1]))
    d, _, lab = g.nearest(o, 5.0)
    assert lab == 1 and abs(d - 2.0) < 0.05  # the nearer square has not passed the threshold
    for _ in range(200):
        g.update(o, np.linspace(0, 6, 50), np.full(50, 3.0), np.zeros(50, dtype=int))
    assert g.nbytes == size and g.updates == 202
