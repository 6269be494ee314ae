"""AMAPS count grid (thesis Ch. 4, Fig. 4.4): counts, forgetting, threshold, r_imin, memory."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.prediction.amaps import AmapsConfig, AmapsGrid
from uvnav.prediction.amaps_kernels import load_kernel


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


# ------------------------------------------------------------------------------------------------
# the fast paths against the original implementation
# ------------------------------------------------------------------------------------------------


class ReferenceAmaps:
    """The original (issue 5, first session) AMAPS update and queries, kept verbatim as the
    reference the optimised numpy and numba paths must match bit for bit."""

    def __init__(self, grid: AmapsGrid) -> None:
        self.config = grid.config
        self.x0, self.y0, self.nx, self.ny = grid.x0, grid.y0, grid.nx, grid.ny
        self._stored = np.zeros((self.ny, self.nx), dtype=np.float32)
        self._gain = 1.0
        self.labels = np.full((self.ny, self.nx), -1, dtype=np.int16)

    def cell_of(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        p = np.asarray(points, dtype=float)
        c = np.floor((p[:, 0] - self.x0) / self.config.cell).astype(np.intp)
        r = np.floor((p[:, 1] - self.y0) / self.config.cell).astype(np.intp)
        ok = (c >= 0) & (c < self.nx) & (r >= 0) & (r < self.ny)
        return c, r, ok

    def update(self, origin: np.ndarray, angles: np.ndarray, ranges: np.ndarray,
               hit_ids: np.ndarray) -> None:  # fmt: skip
        cfg = self.config
        h = cfg.cell
        if cfg.decay < 1.0:
            self._gain *= cfg.decay
            if self._gain < 1e-12:
                self._stored *= np.float32(self._gain)
                self._gain = 1.0
        inv = 1.0 / self._gain
        ok = np.isfinite(ranges)
        ang = np.asarray(angles, dtype=float)[ok]
        rr = np.asarray(ranges, dtype=float)[ok]
        ids = np.asarray(hit_ids)[ok]
        dirs = np.stack([np.cos(ang), np.sin(ang)], axis=-1)
        o = np.asarray(origin, dtype=float)
        step = 0.5 * h
        view = self._stored.reshape(self.nx * self.ny)
        if cfg.free_weight > 0 and len(rr):
            fs = cfg.free_step * h
            n_s = int(np.ceil(min(float(rr.max()), cfg.free_range) / fs)) + 1
            s = np.arange(n_s) * fs
            limit = np.minimum(np.where(ids >= 0, rr - h, rr), cfg.free_range)
            bi, si = np.nonzero(s[None, :] < limit[:, None])
            c = np.floor((o[0] - self.x0 + s[si] * dirs[bi, 0]) / h).astype(np.intp)
            r = np.floor((o[1] - self.y0 + s[si] * dirs[bi, 1]) / h).astype(np.intp)
            inside = (c >= 0) & (c < self.nx) & (r >= 0) & (r < self.ny)
            flat = r[inside] * self.nx + c[inside]
            if len(flat):
                view[flat] = np.maximum(view[flat] - np.float32(cfg.free_weight * inv), 0.0)
        hit = ids >= 0
        if np.any(hit):
            n_d = int(np.floor(cfg.hit_depth / step)) + 1
            s = np.arange(n_d) * step
            pts = o + (rr[hit, None, None] + s[None, :, None]) * dirs[hit, None, :]
            lab = np.repeat(ids[hit], n_d)
            c, r, inside = self.cell_of(pts.reshape(-1, 2))
            flat = r[inside] * self.nx + c[inside]
            view[flat] += np.float32(cfg.hit_weight * inv)
            self.labels.reshape(self.nx * self.ny)[flat] = lab[inside].astype(np.int16)

    def occupied(self, point: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
        h = self.config.cell
        p = np.asarray(point, dtype=float)
        c0 = max(int(np.floor((p[0] - radius - self.x0) / h)), 0)
        c1 = min(int(np.floor((p[0] + radius - self.x0) / h)) + 1, self.nx)
        r0 = max(int(np.floor((p[1] - radius - self.y0) / h)), 0)
        r1 = min(int(np.floor((p[1] + radius - self.y0) / h)) + 1, self.ny)
        rs, cs = slice(r0, max(r1, r0)), slice(c0, max(c1, c0))
        sub = self._stored[rs, cs]
        rows, cols = np.nonzero(sub >= np.float32(self.config.threshold / self._gain))
        rows = rows + rs.start
        cols = cols + cs.start
        centres = np.stack([self.x0 + (cols + 0.5) * h, self.y0 + (rows + 0.5) * h], axis=-1)
        d = np.hypot(centres[:, 0] - p[0], centres[:, 1] - p[1])
        keep = d <= radius
        return centres[keep], self.labels[rows[keep], cols[keep]].astype(np.intp)


ENGINES = ["numpy"] + (["numba"] if load_kernel() is not None else [])


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    cell=st.sampled_from([0.05, 0.037, 0.1]),
    decay=st.sampled_from([1.0, 0.99, 0.3]),
    free_weight=st.sampled_from([0.0, 0.35, 2.0]),
    hit_depth=st.sampled_from([0.0, 0.1, 0.23]),
    free_range=st.sampled_from([1.0, 3.0, 20.0]),
)
def test_fast_paths_match_the_reference_bit_for_bit(
    seed: int, cell: float, decay: float, free_weight: float, hit_depth: float, free_range: float
) -> None:
    """Random sweeps (beams leaving the grid, NaN dropouts, no-return beams, repeated squares):
    counts, labels and every query equal the original implementation's exactly."""
    rng = np.random.default_rng(seed)
    cfg = AmapsConfig(cell=cell, decay=decay, free_weight=free_weight, hit_depth=hit_depth,
                      free_range=free_range)  # fmt: skip
    grids = [
        AmapsGrid.covering(np.zeros(2), np.array([6.0, 4.0]), cfg, margin=1.0, engine=e)
        for e in ENGINES
    ]
    ref = ReferenceAmaps(grids[0])
    for _ in range(12):
        o = rng.uniform(-2.0, 8.0, 2)  # sometimes outside the grid
        b = int(rng.integers(1, 60))
        ang = np.sort(rng.uniform(-4.0, 4.0, b))
        rr = rng.uniform(0.0, 6.0, b)
        ids = rng.integers(-1, 3, b)
        rr[rng.random(b) < 0.1] = np.nan
        ref.update(o, ang, rr, ids)
        for g in grids:
            g.update(o, ang, rr, ids)
    for g in grids:
        assert np.array_equal(g._stored, ref._stored) and g._gain == ref._gain
        assert np.array_equal(g.labels, ref.labels)
        for _ in range(4):
            p = rng.uniform(-1.0, 7.0, 2)
            radius = float(rng.uniform(0.1, 4.0))
            want_c, want_l = ref.occupied(p, radius)
            got_c, got_l = g.occupied(p, radius)
            assert np.array_equal(got_c, want_c) and np.array_equal(got_l, want_l)
            d, centre, lab = g.nearest(p, radius)
            if len(want_c) == 0:
                assert centre is None and d == np.inf and lab == -1
            else:
                dd = np.hypot(want_c[:, 0] - p[0], want_c[:, 1] - p[1])
                j = int(np.argmin(dd))
                assert d == dd[j] and np.array_equal(centre, want_c[j]) and lab == want_l[j]
            # a wider scan filtered to the radius is the narrow scan (the law's single scan)
            wide_c, wide_l, wide_d = g.covered(p, radius + 1.0)
            keep = wide_d <= radius
            assert np.array_equal(wide_c[keep], want_c) and np.array_equal(wide_l[keep], want_l)


def test_engine_choice_is_checked() -> None:
    import pytest

    with pytest.raises(ValueError, match="engine"):
        AmapsGrid((0.0, 0.0), (2, 2), AmapsConfig(), engine="gpu")
    g = AmapsGrid((0.0, 0.0), (2, 2), AmapsConfig(), engine="numpy")
    assert g.engine == "numpy"
