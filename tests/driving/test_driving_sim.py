"""The CarRacing simulator wrapper, the expert, and closed-loop evaluation (short episodes)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("Box2D")

from uvnav.driving.evaluate import (
    PISpeedController,
    autonomy_score,
    expert_policy,
    run_closed_loop,
    speed_law_throttle,
)
from uvnav.driving.expert import PurePursuitExpert, ar1_noise
from uvnav.driving.sim import HALF_WIDTH, DrivingSim


@pytest.fixture(scope="module")
def sim():
    s = DrivingSim(max_steps=300)
    yield s
    s.close()


def test_reset_is_deterministic_and_frames_have_the_camera_shape(sim) -> None:
    f1, t1 = sim.reset(3)
    f2, t2 = sim.reset(3)
    assert f1.shape == (66, 200, 3) and f1.dtype == np.uint8
    assert np.array_equal(f1, f2) and t1 == t2
    assert abs(t1.centre_distance) < 0.5 and abs(t1.heading_error) < 0.1
    left, centre, right = sim.side_views()
    assert not np.array_equal(left, right)
    # straight ahead and near, the centre camera sees road (grey); the top rows see sky (blue)
    low = centre[46:, 50:150].reshape(-1, 3).astype(int)
    grey = (np.abs(low[:, 0] - low[:, 1]) < 15) & (np.abs(low[:, 1] - low[:, 2]) < 15)
    assert grey.mean() > 0.8
    top = centre[:3].reshape(-1, 3).astype(int)
    assert np.all(top[:, 2] > top[:, 0])


def test_positive_steer_turns_right(sim) -> None:
    _, tel = sim.reset(5)
    for _ in range(40):
        tel = sim.step(0.0, 0.4).telemetry
    h0 = tel.heading
    for _ in range(30):
        tel = sim.step(1.0, 0.0).telemetry
    assert tel.heading < h0 - 0.2


def test_expert_drives_along_the_track(sim) -> None:
    _, tel = sim.reset(7)
    expert = PurePursuitExpert(sim.geometry)
    worst = 0.0
    for _ in range(250):
        tel = sim.step(*expert.act(tel)).telemetry
        worst = max(worst, abs(tel.centre_distance))
    assert tel.tiles_visited > 0.15 * tel.n_tiles  # ~1/5 of the lap in 5 s
    assert worst < HALF_WIDTH
    assert tel.speed > 20.0


def test_closed_loop_metrics_of_the_expert(sim) -> None:
    r = run_closed_loop(sim, expert_policy(sim), 11, max_steps=200)
    assert r.interventions == 0 and r.autonomy == 1.0
    assert r.ret > 100.0 and r.steps == 200 and r.laps == 0


def test_interventions_put_the_car_back(sim) -> None:
    # full right lock and gas leaves the road quickly; every exit is one intervention
    r = run_closed_loop(sim, lambda f, t: (1.0, 0.5), 2, max_steps=300)
    assert r.interventions >= 1
    assert r.autonomy == pytest.approx(autonomy_score(r.interventions, r.steps / 50))
    assert r.autonomy < 1.0


def test_autonomy_formula_and_pi_controller() -> None:
    assert autonomy_score(0, 60.0) == 1.0
    assert autonomy_score(1, 600.0) == pytest.approx(0.99)
    assert autonomy_score(20, 60.0) == 0.0
    pi = PISpeedController(set_speed=30.0)
    assert pi(10.0) > 0 and pi(50.0) < 0


def test_ar1_noise_statistics() -> None:
    e = ar1_noise(np.random.default_rng(0), 20000, sigma=0.3, rho=0.9)
    assert abs(e.std() - 0.3) < 0.03
    assert abs(np.corrcoef(e[:-1], e[1:])[0, 1] - 0.9) < 0.03


def test_expert_target_speed_label_gives_its_throttle(sim) -> None:
    """The recorded target speed: the expert's pedal is the P law on it, and it slows corners."""
    _, tel = sim.reset(7)
    expert = PurePursuitExpert(sim.geometry)
    targets, curv = [], []
    for _ in range(250):
        steer, throttle, v_target = expert.label(tel)
        assert (steer, throttle) == expert.act(tel)
        assert throttle == pytest.approx(speed_law_throttle(v_target, tel.speed))
        targets.append(v_target)
        curv.append(float(np.abs(sim.geometry.curvature).max()))
        tel = sim.step(steer, throttle).telemetry
    p = expert.params
    v_corner = np.sqrt(p.a_lat / max(curv))  # the tightest corner's speed limit
    assert min(targets) >= v_corner - 1e-6 and max(targets) <= p.v_max
    assert max(targets) - min(targets) > 10.0  # it does change along the track


def test_side_camera_sees_the_centre_view_of_a_shifted_car_and_gets_its_label(sim) -> None:
    """A side image is the centre camera's image at the shifted pose; its label is the expert's
    command there: left of the line, steer right (+), and the reverse."""
    from dataclasses import replace

    from uvnav.driving.camera import render_view

    _, tel = sim.reset(4)
    for _ in range(60):
        tel = sim.step(0.0, 0.5).telemetry
    expert = PurePursuitExpert(sim.geometry)
    s = sim.side_shift
    nx, ny = -np.sin(tel.heading), np.cos(tel.heading)
    left, _, right = sim.side_views()
    for side, img in ((1.0, left), (-1.0, right)):
        at = render_view(
            sim._raster, sim._rays, tel.x + side * s * nx, tel.y + side * s * ny, tel.heading
        )
        assert np.mean(np.all(at == img, axis=-1)) > 0.999  # rounding at a few edges only
    e_left, e_right = expert.side_steering(tel, s)
    moved = replace(tel, x=tel.x + s * nx, y=tel.y + s * ny)
    assert e_left == pytest.approx(expert.label(moved)[0])
    steer = expert.label(tel)[0]
    assert e_left > steer + 0.05 and e_right < steer - 0.05
    # the exact correction shrinks as the lookahead grows with speed (a fixed ±0.2 cannot)
    fast = replace(tel, speed=tel.speed + 40.0)
    f_left, f_right = expert.side_steering(fast, s)
    assert f_left - f_right < e_left - e_right


def test_step_on_track_puts_the_car_back_and_keeps_where_it_left(sim) -> None:
    sim.reset(2)
    for _ in range(300):  # full right lock and gas: off the road within a few seconds
        st = sim.step_on_track(1.0, 0.5)
        if st.left is not None:
            break
    assert st.left is not None and st.left.off_track  # the reading that left the track
    assert not st.telemetry.off_track and st.telemetry.speed == 0.0  # back, at rest
    assert st.frame.shape == sim.frame().shape
    assert sim.step_on_track(0.0, 0.0).left is None  # on the track: a plain step
