"""Viewing-cone sonar (thesis Ch. 4 §4.2, Fig. 4.3): visible part only, extremes, noise,
dropout, and the narrow-opening detector of Fig. 4.2(b)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.obstacles.deforming import DeformingStar, trap_polygon
from uvnav.sensors.sonar2d import SonarConfig, close_narrow_openings, sonar_scan
from uvnav.sensors.sonar2d_kernels import load_pairs_kernel


def square(cx: float, cy: float, h: float) -> np.ndarray:
    return np.array([[cx - h, cy - h], [cx + h, cy - h], [cx + h, cy + h], [cx - h, cy + h]])


def test_occluded_obstacle_is_not_seen_and_only_the_near_face_is() -> None:
    near = square(3.0, 0.0, 0.5)
    far = square(6.0, 0.0, 0.3)  # entirely hidden behind ``near`` from the origin
    cfg = SonarConfig(n_beams=181, fov=np.pi / 2, max_range=10.0)
    r = sonar_scan(np.array([0.0, 0.0, 0.0]), [near, far], np.random.default_rng(0), cfg)
    assert list(r.ids) == [0]
    pts = r.points[r.hit_ids == 0]
    assert np.allclose(pts[:, 0], 2.5)  # every return lies on the facing edge x = 2.5
    assert abs(r.d_min[0] - 2.5) < 1e-9
    assert np.allclose(r.r_min[0], [2.5, 0.0], atol=1e-9)
    assert r.d_max[0] > 2.5


@settings(max_examples=30, deadline=None)
@given(
    x=st.floats(-3, 3),
    y=st.floats(-3, 3),
    th=st.floats(-np.pi, np.pi),
    fov=st.floats(0.3, 2 * np.pi),
)
def test_returns_are_first_hits_on_the_outlines(x: float, y: float, th: float, fov: float) -> None:
    obs = [square(4.0, 0.5, 0.6), square(-1.0, 4.0, 0.4)]
    if any(shapely.contains_xy(shapely.polygons(o), x, y) for o in obs):
        return
    cfg = SonarConfig(n_beams=37, fov=fov, max_range=8.0)
    r = sonar_scan(np.array([x, y, th]), obs, np.random.default_rng(0), cfg)
    rel = np.angle(np.exp(1j * (r.angles - th)))
    assert np.all(np.abs(rel) <= fov / 2 + 1e-9)  # beams inside the viewing cone
    union = shapely.union_all([shapely.polygons(o) for o in obs])
    for a, rng_, hid in zip(r.angles, r.ranges, r.hit_ids, strict=True):
        seg = shapely.linestrings([[x, y], [x + 8 * np.cos(a), y + 8 * np.sin(a)]])
        inter = shapely.intersection(seg, union)
        if hid < 0:
            assert rng_ == 8.0 and (
                inter.is_empty or shapely.distance(shapely.points(x, y), inter) > 8 - 1e-9
            )
        else:
            assert abs(rng_ - shapely.distance(shapely.points(x, y), inter)) < 1e-7


def test_noise_and_dropout_are_seeded() -> None:
    cfg = SonarConfig(n_beams=61, fov=np.pi, max_range=10.0, noise_std=0.05, dropout=0.2)
    obs = [square(3.0, 0.0, 1.0)]
    a = sonar_scan(np.zeros(3), obs, np.random.default_rng(5), cfg)
    b = sonar_scan(np.zeros(3), obs, np.random.default_rng(5), cfg)
    assert np.array_equal(a.ranges, b.ranges, equal_nan=True)
    assert np.isnan(a.ranges).sum() > 0
    clean = sonar_scan(np.zeros(3), obs, np.random.default_rng(5), SonarConfig(61, np.pi, 10.0))
    hit = a.hit_ids >= 0
    err = a.ranges[hit] - clean.ranges[hit]
    assert 0.02 < float(np.std(err)) < 0.09


def test_narrow_mouth_is_closed_and_wide_one_is_not() -> None:
    trap = trap_polygon((3.0, 0.0), outer=1.5, inner=1.0, mouth=0.3, facing=np.pi)
    cfg = SonarConfig(n_beams=361, fov=np.pi / 2, max_range=10.0)
    r = sonar_scan(np.zeros(3), [trap], np.random.default_rng(0), cfg)
    assert r.d_max[0] > 3.5  # beams through the mouth see the far inner wall (a << b)
    ranges, ids = close_narrow_openings(r.origin, r.angles, r.ranges, r.hit_ids, width=0.5)
    seen = r.hit_ids >= 0
    inside = seen & (np.abs(r.angles) < np.arctan2(0.15, 1.5))  # beams through the mouth
    assert inside.sum() >= 3
    assert ranges[inside].max() < 1.6  # clipped to the mouth at x = 1.5
    # elsewhere at most the sagitta of a chord shorter than the width
    assert np.allclose(ranges[seen & ~inside], r.ranges[seen & ~inside], atol=0.05)
    assert np.all(ids[seen] == 0)
    wide, _ = close_narrow_openings(r.origin, r.angles, r.ranges, r.hit_ids, width=0.2)
    # a vehicle narrower than the mouth could enter: the beams through it are left alone
    deep = inside & (r.ranges > 3.5)
    assert deep.sum() >= 3 and np.all(wide[deep] > 3.5)
    assert np.allclose(wide, r.ranges, atol=0.05)


@pytest.mark.skipif(load_pairs_kernel() is None, reason="numba (extra 'fast') not installed")
@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_bodies=st.integers(1, 4),
    width=st.floats(0.2, 2.5),
    noisy=st.booleans(),
)
def test_compiled_opening_detector_matches_the_numpy_one(
    seed: int, n_bodies: int, width: float, noisy: bool
) -> None:
    """The compiled pair search closes exactly the beams the numpy matrices do."""
    rng = np.random.default_rng(seed)
    bodies = [
        DeformingStar.random(
            rng, tuple(rng.uniform(2, 8, 2)), float(rng.uniform(0.3, 3.0)), max_rate=0.2
        )
        for _ in range(n_bodies)
    ]
    pose = np.array([*rng.uniform(0, 10, 2), rng.uniform(-3, 3)])
    cfg = SonarConfig(noise_std=0.05 if noisy else 0.0, dropout=0.1 if noisy else 0.0)
    r = sonar_scan(pose, [b.outline(float(rng.uniform(0, 10))) for b in bodies], rng, cfg)
    want = close_narrow_openings(r.origin, r.angles, r.ranges, r.hit_ids, width, engine="numpy")
    got = close_narrow_openings(r.origin, r.angles, r.ranges, r.hit_ids, width)
    assert np.array_equal(got[0], want[0], equal_nan=True) and np.array_equal(got[1], want[1])
