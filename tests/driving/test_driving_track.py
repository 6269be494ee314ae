"""Track geometry kernels: projection, lookahead, corner-speed profile (property tests)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.driving.track import corner_speed_profile, point_ahead, project, track_geometry


def _circle(radius: float, n: int = 400) -> np.ndarray:
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.stack([radius * np.cos(a), radius * np.sin(a)], axis=1)  # counter-clockwise


@settings(max_examples=60, deadline=None)
@given(st.floats(20, 200), st.floats(0, 2 * np.pi), st.floats(-10, 10))
def test_signed_distance_on_a_circle(radius: float, angle: float, offset: float) -> None:
    g = track_geometry(_circle(radius))
    r = radius - offset  # + offset = towards the centre = left of counter-clockwise travel
    _, _, d = project(g, r * np.cos(angle), r * np.sin(angle))
    assert abs(d - offset) < 0.01 * radius + 1e-6


@settings(max_examples=30, deadline=None)
@given(st.floats(30, 200), st.floats(1, 50))
def test_point_ahead_is_at_the_arc_distance(radius: float, dist: float) -> None:
    g = track_geometry(_circle(radius))
    i, t, _ = project(g, radius, 0.0)
    p = point_ahead(g, i, t, dist)
    chord = 2 * radius * np.sin(dist / (2 * radius))
    assert abs(np.hypot(p[0] - radius, p[1]) - chord) < 0.02 * dist + 1e-6


def test_curvature_and_speed_profile() -> None:
    g = track_geometry(_circle(100.0))
    assert np.allclose(g.curvature, 0.01, rtol=0.02)
    assert abs(g.length - 2 * np.pi * 100) < 1.0
    v = corner_speed_profile(g, v_max=80.0, a_lat=50.0, a_brake=20.0)
    assert np.allclose(v, np.sqrt(50.0 / 0.01), rtol=0.02)
    # a straight into a tight corner: the profile brakes within a_brake before it
    straight = np.stack([np.linspace(0, 300, 100), np.zeros(100)], 1)
    pts = np.concatenate([straight, _circle(20.0)[:50] + np.array([300.0, 20.0])])
    g2 = track_geometry(pts)
    v2 = corner_speed_profile(g2, v_max=80.0, a_lat=50.0, a_brake=20.0)
    assert v2.max() <= 80.0
    dv2 = v2[:-1] ** 2 - v2[1:] ** 2
    assert np.all(dv2 <= 2 * 20.0 * g2.seg_len[:-1] + 1e-6)
