"""zhang2022-uuv2d-v1 (thesis Ch. 4 §4.3): tag, count (4.12), forecast radius (4.11), tangent
waypoint (4.13), limits, and the Fig. 4.7 approach phase."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.base import available_controllers, make_law
from uvnav.controllers.zhang2022_uuv2d import Zhang2022Uuv2dController
from uvnav.dynamics.holonomic import HolonomicSpec
from uvnav.obstacles.deforming import DeformingStar
from uvnav.prediction.amaps import AmapsConfig, AmapsGrid
from uvnav.prediction.amaps_kernels import load_kernel
from uvnav.scenarios.uuv2d import load_uuv2d_scenario
from uvnav.sensors.sonar2d import SonarConfig, SonarObservation, sonar_scan
from uvnav.sim.run import run_episode

SPEC = HolonomicSpec(v_max=1.0, u_max=2.0, radius=0.2)
GOAL = np.array([10.0, 10.0])


def observe(pose: np.ndarray, outlines: list[np.ndarray], centres: np.ndarray, t: float = 0.0):
    reading = sonar_scan(pose, outlines, np.random.default_rng(0), SonarConfig(), centres=centres)
    return SonarObservation(t, pose, np.zeros(2), GOAL, reading, 0.2)


def test_registry_holds_the_law_and_both_baselines() -> None:
    assert {"zhang2022-uuv2d-v1", "apf-uuv2d-v1", "zhang2019-uuv2d-v1"} <= set(
        available_controllers("uuv2d")
    )
    with pytest.raises(KeyError):
        make_law("nope", vehicle="uuv2d")


def test_direction_tag_is_the_side_of_the_mass_centre() -> None:
    tag = Zhang2022Uuv2dController.direction_tag
    assert tag(np.zeros(2), GOAL, np.array([4.0, 6.0])) == 1  # CCW of the line to E
    assert tag(np.zeros(2), GOAL, np.array([6.0, 4.0])) == -1


@pytest.mark.parametrize("outer", [False, True])
def test_avoidance_waypoint_is_a_tangent_away_from_the_mass_centre(outer: bool) -> None:
    # a disc-like body centred right of the I->E line, its near side across the line
    body = DeformingStar.create((2.4, 2.0), math.pi * 0.8**2, np.zeros((1, 2)), max_rate=0.0)
    outline = body.outline(0.0)
    ctrl = make_law("zhang2022-uuv2d-v1", vehicle="uuv2d", outer_tangent=outer)
    ctrl.reset(SPEC, GOAL, np.random.default_rng(0))
    pose = np.array([1.0, 1.0, math.pi / 4])
    cmd = ctrl.act(observe(pose, [outline], np.array([[2.4, 2.0]])))
    d = ctrl.last
    assert d is not None and d.mode == "M2" and d.tag == -1  # centre is clockwise of the line
    assert d.count == 1
    # rho = R_i (0 at the first step) + radius + safety margin
    assert math.isclose(d.radius, SPEC.radius + ctrl.params.safety_margin)
    wp = d.waypoint
    assert wp is not None and d.r_min is not None
    to_r = d.r_min - pose[:2]
    to_w = wp - pose[:2]
    # on the side away from the mass centre: counter-clockwise of the line to r_imin
    assert to_r[0] * to_w[1] - to_r[1] * to_w[0] > 0
    if not outer:  # the literal (4.13): the tangent point of r_imin's forecast circle
        assert math.isclose(float(np.hypot(*(wp - d.r_min))), d.radius, rel_tol=1e-9)
        assert abs(float(np.dot(wp - pose[:2], wp - d.r_min))) < 1e-9
    else:  # the line ahead clears every covered square's forecast circle (within L, in front)
        assert ctrl.grid is not None
        centres, _ = ctrl.grid.occupied(pose[:2], ctrl.params.switch_distance)
        u = to_w / np.hypot(*to_w)
        along = (centres - pose[:2]) @ u
        perp = np.abs((centres - pose[:2]) @ np.array([-u[1], u[0]]))
        ahead = along > 0
        assert np.all(perp[ahead] >= d.radius - 1e-9)
    v = np.array([cmd.vx, cmd.vy])
    assert not cmd.violates(SPEC, pose[2], 0.2)
    assert np.hypot(*v) > 0


def test_count_and_forecast_radius_follow_4_11_and_4_12() -> None:
    body = DeformingStar.create((3.0, 3.0), math.pi * 0.8**2, np.zeros((1, 2)), max_rate=0.0)
    ctrl = make_law("zhang2022-uuv2d-v1", vehicle="uuv2d")
    ctrl.reset(SPEC, GOAL, np.random.default_rng(0))
    centres = np.array([[3.0, 3.0]])
    path = [np.array([1.55, 1.55]), np.array([1.6, 1.5]), np.array([1.7, 1.45])]
    seen = []
    for k, p in enumerate(path):
        ctrl.act(observe(np.array([p[0], p[1], math.pi / 4]), [body.outline(0)], centres, 0.2 * k))
        seen.append(ctrl.last)
    assert [d.count for d in seen] == [1, 2, 3]
    r = np.array([d.r_min for d in seen])
    expected = float(np.hypot(*np.diff(r, axis=0).T).mean())
    assert seen[-1].extra["R_i"] == expected  # the same arithmetic as (4.11) written out
    # far from everything: count(t) = 0 and target approaching
    ctrl.act(observe(np.array([-6.0, -6.0, math.pi / 4]), [body.outline(0)], centres, 1.0))
    assert ctrl.last is not None and ctrl.last.mode == "M1" and ctrl._count == 0


@settings(max_examples=25, deadline=None)
@given(
    x=st.floats(-1.0, 6.0),
    y=st.floats(-1.0, 6.0),
    th=st.floats(-math.pi, math.pi),
    seed=st.integers(0, 1000),
)
def test_commands_stay_within_the_limits(x: float, y: float, th: float, seed: int) -> None:
    body = DeformingStar.random(np.random.default_rng(seed), (3.0, 3.0), 2.0, max_rate=0.2)
    ctrl = make_law("zhang2022-uuv2d-v1", vehicle="uuv2d")
    ctrl.reset(SPEC, GOAL, np.random.default_rng(0))
    pose = np.array([x, y, th])
    for k in range(3):
        cmd = ctrl.act(observe(pose, [body.outline(0.2 * k)], np.array([[3.0, 3.0]]), 0.2 * k))
        assert math.isfinite(cmd.vx) and math.isfinite(cmd.vy)
        assert not cmd.violates(SPEC, th, 0.2)


def test_fig_4_7_target_approaching_for_t_0_to_4() -> None:
    """Fig. 4.7: from t = 0 to 4 the UUV runs straight at E at sqrt(2) V_max while d_imin > L."""
    sc = load_uuv2d_scenario("thesis-ch4-fig4-7-approach")
    setup = sc.to_setup()
    setup.t_max = 4.2
    res = run_episode(
        setup, make_law(sc.controller.name, vehicle="uuv2d"), np.random.default_rng(0)
    )
    tr = res.trajectory
    assert tr is not None and res.status == "timeout"
    early = tr.decision_times <= 4.0 + 1e-9
    assert all(m == "M1" for m, e in zip(tr.modes, early, strict=True) if e)
    assert all(d.d_min > sc.switch_distance for d, e in zip(tr.decisions, early, strict=True) if e)
    at4 = tr.poses[np.searchsorted(tr.times, 4.0)]
    assert np.allclose(at4[:2], [4.0, 4.0], atol=1e-6)  # sqrt(2) V_max along the diagonal


@pytest.mark.skipif(load_kernel() is None, reason="numba (extra 'fast') not installed")
def test_decisions_are_the_same_with_either_amaps_engine() -> None:
    """The compiled AMAPS path changes no decision: same commands, modes, r_imin and R_i."""
    body = DeformingStar.random(np.random.default_rng(3), (5.0, 5.0), 3.0, max_rate=0.3)
    centres = np.array([[5.0, 5.0]])
    seen: dict[str, list[tuple[object, ...]]] = {}
    for engine in ("numpy", "numba"):
        ctrl = make_law("zhang2022-uuv2d-v1", vehicle="uuv2d")
        ctrl.reset(SPEC, GOAL, np.random.default_rng(0))
        assert isinstance(ctrl, Zhang2022Uuv2dController)
        ctrl.grid = AmapsGrid.covering(
            np.zeros(2), GOAL, AmapsConfig(cell=0.05), margin=4.0, engine=engine
        )
        out = []
        for k in range(40):
            a = 2 * math.pi * k / 40
            pose = np.array([5 + 2.0 * math.cos(a), 5 + 2.0 * math.sin(a), a + math.pi / 2])
            cmd = ctrl.act(observe(pose, [body.outline(0.2 * k)], centres, 0.2 * k))
            d = ctrl.last
            assert d is not None
            r_min = None if d.r_min is None else tuple(d.r_min)
            out.append((cmd.vx, cmd.vy, d.mode, r_min, d.radius, d.extra.get("R_i")))
        seen[engine] = out
    assert seen["numpy"] == seen["numba"]
    assert any(o[2] == "M2" for o in seen["numpy"])  # avoidance decisions were compared too


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), r=st.floats(0.0, 4.0))
def test_one_scan_answers_like_separate_scans(seed: int, r: float) -> None:
    """The law's single window scan, filtered, equals a grid scan of the smaller radius."""
    from uvnav.controllers.zhang2022_uuv2d import _Near

    rng = np.random.default_rng(seed)
    grid = AmapsGrid.covering(np.zeros(2), np.full(2, 6.0), AmapsConfig(decay=1.0))
    for _ in range(5):
        b = int(rng.integers(1, 40))
        grid.update(rng.uniform(0, 6, 2), rng.uniform(-4, 4, b), rng.uniform(0.2, 3, b),
                    rng.integers(-1, 3, b))  # fmt: skip
    p = rng.uniform(0, 6, 2)
    near = _Near(*grid.covered(p, 3.0), 3.0)
    rr = min(r, 3.0)
    want_c, want_l = grid.occupied(p, rr)
    got_c, got_l = near.within(rr)
    assert np.array_equal(got_c, want_c) and np.array_equal(got_l, want_l)
    d, c, lab = near.nearest(rr)
    wd, wc, wl = grid.nearest(p, rr)
    assert d == wd and lab == wl and (c is None) == (wc is None)
    assert c is None or np.array_equal(c, wc)


@pytest.mark.parametrize("seed", [12, 32])
def test_the_passing_side_is_kept_when_r_min_moves_to_another_body(seed: int) -> None:
    """Hard scenes where r_imin alternates between two bodies: re-drawing the tag at each switch
    turned the vehicle back between them and a moving body hit it (these seeds collided).  With
    the tag kept while count(t) > 0 the vehicle reaches E clear of every body."""
    from uvnav.scenarios.uuv2d import random_ch4_hard_scenario

    sc = random_ch4_hard_scenario(seed)
    res = run_episode(
        sc.to_setup(), make_law("zhang2022-uuv2d-v1", vehicle="uuv2d"), np.random.default_rng(seed)
    )
    assert res.status == "success"
    assert res.metrics.min_clearance > 0.05
