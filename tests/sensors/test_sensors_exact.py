"""Exact range-limited sensing (thesis eq. (2.5)) and the lidar scanner."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from shapely.geometry import LineString, Point, Polygon

from uvnav.obstacles import (
    ConstantVelocity,
    DiscBody,
    Obstacle,
    ObstacleField,
    ObstacleState,
    PolygonBody,
)
from uvnav.sensors import lidar_scan, sense_obstacles
from uvnav.sensors.exact import beam_directions, beam_offsets, beam_turns
from uvnav.sensors.observation import Readings, read_arrays

ARROW = np.array([[-0.6, -0.4], [0.7, -0.5], [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]])


def _ring_world(k: int = 12, seed: int = 0) -> ObstacleField:
    """``k`` obstacles (discs alternating with non-convex polygons) at distances 1.5..k+0.5 m."""
    rng = np.random.default_rng(seed)
    obs = []
    for j in range(k):
        d = 1.5 + j
        a = rng.uniform(-math.pi, math.pi)
        body = DiscBody(0.3) if j % 2 else PolygonBody.from_vertices(0.5 * ARROW)
        st = ObstacleState(
            position=d * np.array([math.cos(a), math.sin(a)]),
            heading=float(rng.uniform(-3, 3)),
            velocity=rng.normal(size=2),
            angular_velocity=float(rng.normal()),
        )
        obs.append(Obstacle(body, st, ConstantVelocity(st.velocity)))
    return ObstacleField.from_obstacles(obs)


@pytest.mark.parametrize("sensing_range", [0.0, 2.0, 4.5, 7.0, math.inf])
def test_sensing_range_filters_and_sorts(sensing_range: float) -> None:
    fld = _ring_world()
    p = np.array([0.2, -0.1])
    dist, _, _ = fld.nearest(p)
    readings = sense_obstacles(p, fld, sensing_range=sensing_range)
    expected = {j for j in range(len(fld)) if dist[j] <= sensing_range}
    assert {r.obstacle_id for r in readings} == expected
    ds = [r.distance for r in readings]
    assert ds == sorted(ds)
    for r in readings:
        j = r.obstacle_id
        assert r.distance == pytest.approx(dist[j])
        assert r.centre == pytest.approx(fld.centres[j])
        assert r.velocity == pytest.approx(fld.velocities[j])
        assert r.angular_velocity == fld.angular_velocities[j]
        assert r.velocity_source == "known"
        assert float(np.hypot(*(r.nearest_point - p))) == pytest.approx(r.distance, abs=1e-12)
        if fld.polygons[j] is None:
            assert r.is_disc and r.outline.shape == (0, 2) and r.radius == 0.3
        else:
            assert not r.is_disc and np.array_equal(r.outline, fld.polygons[j])


def test_readings_do_not_alias_the_field() -> None:
    fld = _ring_world(4)
    r = sense_obstacles(np.zeros(2), fld)[0]
    r.centre[0] += 100.0
    r.nearest_point[0] += 100.0
    assert sense_obstacles(np.zeros(2), fld)[0].centre[0] < 50.0


def test_empty_world_senses_nothing() -> None:
    assert sense_obstacles(np.zeros(2), ObstacleField.from_obstacles([])) == ()


def test_inside_an_obstacle_reports_zero_distance() -> None:
    ob = Obstacle(
        PolygonBody.from_vertices(ARROW),
        ObstacleState(position=np.zeros(2)),
        ConstantVelocity(np.zeros(2)),
    )
    (r,) = sense_obstacles(
        np.array([-0.2, 0.0]), ObstacleField.from_obstacles([ob]), sensing_range=1.0
    )
    assert r.distance == 0.0
    assert Polygon(r.outline).exterior.distance(Point(r.nearest_point)) < 1e-12


def _shapely_scan(
    fld: ObstacleField, pose: np.ndarray, angles: np.ndarray, max_range: float
) -> np.ndarray:
    geoms = []
    for j in range(len(fld)):
        poly = fld.polygons[j]
        geoms.append(Polygon(poly).exterior if poly is not None else None)
    out = np.full(len(angles), max_range)
    for i, a in enumerate(angles):
        o = pose[:2]
        u = np.array([math.cos(a), math.sin(a)])
        best = max_range
        for j, g in enumerate(geoms):
            if g is None:  # disc: analytic
                m = fld.centres[j] - o
                b = float(u @ m)
                disc = b * b - (float(m @ m) - fld.radii[j] ** 2)
                if disc >= 0:
                    roots = [b - math.sqrt(disc), b + math.sqrt(disc)]
                    ok = [t for t in roots if t >= 0]
                    if ok:
                        best = min(best, ok[0])
            else:
                inter = LineString([o, o + 100.0 * u]).intersection(g)
                if not inter.is_empty:
                    pts = shapely.get_coordinates(inter)
                    best = min(best, float(np.min(np.hypot(*(pts - o).T))))
        out[i] = best
    return out


@pytest.mark.parametrize("fov", [2 * math.pi, math.pi / 2])
def test_lidar_ranges_agree_with_ray_casts(fov: float) -> None:
    fld = _ring_world(10, seed=5)
    pose = np.array([0.1, 0.2, 0.7])
    scan = lidar_scan(pose, fld, n_rays=90, max_range=6.0, fov=fov)
    assert scan.angles.shape == scan.ranges.shape == (90,)
    # world-frame beam angles, wrapped to (-pi, pi]
    assert np.all((scan.angles > -math.pi) & (scan.angles <= math.pi))
    rel = np.remainder(scan.angles - pose[2] + math.pi, 2 * math.pi) - math.pi  # about the heading
    if fov >= 2 * math.pi:
        assert np.allclose(np.remainder(np.diff(rel), 2 * math.pi), 2 * math.pi / 90)
    else:
        assert rel[0] == pytest.approx(-fov / 2) and rel[-1] == pytest.approx(fov / 2)
        assert np.allclose(np.diff(rel), fov / 89)
    ref = _shapely_scan(fld, pose, scan.angles, 6.0)
    assert scan.ranges == pytest.approx(ref, abs=1e-9)
    assert np.any(scan.ranges < 6.0)
    assert scan.max_range == 6.0


@given(st.floats(-1e3, 1e3), st.integers(1, 400))
def test_the_beams_are_unit_vectors_at_heading_plus_offset(theta: float, n_rays: int) -> None:
    """The beams turned by the heading point at ``theta + offset`` within a few 1e-16 (the
    rotation of two rounded unit vectors), and have unit length as closely."""
    rel = beam_offsets(n_rays, 2.0 * math.pi)
    d = beam_directions(theta, beam_turns(rel))
    assert d.shape == (n_rays, 2)
    exact = np.column_stack([np.cos(theta + rel), np.sin(theta + rel)])
    assert np.abs(d - exact).max() <= 1e-13 * (1.0 + abs(theta))
    assert np.abs(np.hypot(d[:, 0], d[:, 1]) - 1.0).max() <= 1e-15


def test_lidar_empty_world_reads_max_range() -> None:
    scan = lidar_scan(np.zeros(3), ObstacleField.from_obstacles([]), n_rays=8, max_range=3.0)
    assert np.array_equal(scan.ranges, np.full(8, 3.0))


@pytest.mark.parametrize("kwargs", [{"noise_std": 0.1}, {"dropout": 0.2}])
def test_noise_and_dropout_need_a_generator(kwargs: dict[str, float]) -> None:
    with pytest.raises(ValueError, match="Generator"):
        lidar_scan(np.zeros(3), _ring_world(3), None, **kwargs)


def test_dropout_rate_and_nan() -> None:
    fld = _ring_world(10, seed=2)
    clean = lidar_scan(np.zeros(3), fld, n_rays=20000, max_range=8.0)
    scan = lidar_scan(
        np.zeros(3), fld, np.random.default_rng(123), n_rays=20000, max_range=8.0, dropout=0.3
    )
    lost = np.isnan(scan.ranges)
    sigma = math.sqrt(0.3 * 0.7 / 20000)
    assert abs(lost.mean() - 0.3) < 4 * sigma
    # beams that survive are untouched
    assert np.array_equal(scan.ranges[~lost], clean.ranges[~lost])


def test_range_noise_statistics() -> None:
    fld = _ring_world(10, seed=2)
    clean = lidar_scan(np.zeros(3), fld, n_rays=20000, max_range=8.0)
    noisy = lidar_scan(
        np.zeros(3), fld, np.random.default_rng(7), n_rays=20000, max_range=8.0, noise_std=0.05
    )
    hit = clean.ranges < 8.0
    assert hit.sum() > 1000
    err = noisy.ranges[hit] - clean.ranges[hit]
    # clipping to [0, max_range] is rare here: mean ~ 0, std ~ noise_std
    assert abs(err.mean()) < 4 * 0.05 / math.sqrt(hit.sum())
    assert err.std() == pytest.approx(0.05, rel=0.05)
    assert np.array_equal(noisy.ranges[~hit], clean.ranges[~hit])  # misses stay at max_range
    assert np.all((noisy.ranges >= 0) & (noisy.ranges <= 8.0))


def test_noisy_scan_is_deterministic_given_seed() -> None:
    fld = _ring_world(6, seed=1)
    a = lidar_scan(np.zeros(3), fld, np.random.default_rng(9), noise_std=0.1, dropout=0.1)
    b = lidar_scan(np.zeros(3), fld, np.random.default_rng(9), noise_std=0.1, dropout=0.1)
    assert np.array_equal(a.ranges, b.ranges, equal_nan=True)


@pytest.mark.parametrize("sensing_range", [0.5, 2.0, 4.5, math.inf])
def test_sensing_reuses_a_wider_query_without_changing_readings(sensing_range: float) -> None:
    """The simulator queries the field once per step (collision check, covering the sensing
    range); sensing then reads that cached answer, with the same result as a fresh field."""
    p = np.array([0.2, -0.1])
    fresh = sense_obstacles(p, _ring_world(), sensing_range=sensing_range)
    fld = _ring_world()
    q = fld.query(p, sensing_range + 1.0, nearest=True)
    cached = sense_obstacles(p, fld, sensing_range=sensing_range)
    assert fld.query(p, sensing_range, nearest=False) is q
    assert len(cached) == len(fresh)
    for a, b in zip(cached, fresh, strict=True):
        assert a.obstacle_id == b.obstacle_id and a.distance == b.distance
        for name in ("nearest_point", "centre", "velocity", "outline"):
            assert np.array_equal(getattr(a, name), getattr(b, name))


@pytest.mark.parametrize("sensing_range", [0.0, 4.5, math.inf])
def test_the_readings_as_arrays_are_the_readings(sensing_range: float) -> None:
    """The sensor's readings give themselves as arrays read from the field, exactly what
    reading each reading gives (discs and polygons), read-only."""
    readings = sense_obstacles(np.array([0.2, -0.1]), _ring_world(), sensing_range=sensing_range)
    assert isinstance(readings, Readings) or readings == ()
    if readings:
        for got, ref in zip(readings.arrays, read_arrays(tuple(readings)), strict=True):
            assert got.shape == ref.shape and np.array_equal(got, ref)
            assert not got.flags.writeable


def test_the_sensor_says_every_velocity_is_known() -> None:
    readings = sense_obstacles(np.zeros(2), _ring_world(), sensing_range=5.0)
    assert isinstance(readings, Readings) and readings.all_known
    assert all(r.velocity_source == "known" for r in readings)
