"""Unicycle kinematics (thesis Ch. 2 eqs. (2.1)-(2.4)): exact arc integration and limits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from uvnav.dynamics.unicycle import (
    Unicycle,
    UnicycleCommand,
    UnicycleSpec,
    turn_then_move,
    unicycle_advance,
    unicycle_step,
)

speed = st.floats(min_value=0.0, max_value=3.0)
rate = st.floats(min_value=-3.0, max_value=3.0)
step = st.floats(min_value=1e-3, max_value=2.0)
pose = st.tuples(st.floats(-50, 50), st.floats(-50, 50), st.floats(-math.pi, math.pi))


def _rk4(state: np.ndarray, v: float, u: float, dt: float, n: int = 400) -> np.ndarray:
    """Classical RK4 of x' = v cos th, y' = v sin th, th' = u (independent reference)."""

    def f(s: np.ndarray) -> np.ndarray:
        return np.array([v * math.cos(s[2]), v * math.sin(s[2]), u])

    s = np.array(state, dtype=float)
    h = dt / n
    for _ in range(n):
        k1 = f(s)
        k2 = f(s + 0.5 * h * k1)
        k3 = f(s + 0.5 * h * k2)
        k4 = f(s + h * k3)
        s = s + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return s


def _same_pose(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    return bool(
        np.allclose(a[:2], b[:2], atol=tol, rtol=0)
        and abs(math.remainder(a[2] - b[2], 2 * math.pi)) <= tol
    )


@settings(max_examples=60, deadline=None)
@given(pose, speed, rate, step)
def test_step_matches_fine_rk4(
    p: tuple[float, float, float], v: float, u: float, dt: float
) -> None:
    s0 = np.array(p)
    out = unicycle_step(s0, v, u, dt)
    ref = _rk4(s0, v, u, dt)
    assert _same_pose(out, ref, 1e-6)
    assert -math.pi < out[2] <= math.pi


@settings(max_examples=200, deadline=None)
@given(pose, speed, rate, step)
@example(p=(0.0, 0.0, 1.0), v=1.0, u=1e-9, dt=1.0)  # one step on the arc branch, halves straight
def test_two_half_steps_equal_one_step(
    p: tuple[float, float, float], v: float, u: float, dt: float
) -> None:
    s0 = np.array(p)
    one = unicycle_step(s0, v, u, dt)
    two = unicycle_step(unicycle_step(s0, v, u, 0.5 * dt), v, u, 0.5 * dt)
    assert _same_pose(one, two, 1e-9 * max(1.0, v * dt))


@settings(max_examples=200, deadline=None)
@given(pose, speed, step)
def test_zero_turn_is_a_straight_line(p: tuple[float, float, float], v: float, dt: float) -> None:
    s0 = np.array(p)
    out = unicycle_step(s0, v, 0.0, dt)
    expect = s0[:2] + v * dt * np.array([math.cos(s0[2]), math.sin(s0[2])])
    assert np.allclose(out[:2], expect, atol=1e-12)
    assert math.remainder(out[2] - s0[2], 2 * math.pi) == pytest.approx(0.0, abs=1e-15)


def test_straight_line_limit_is_continuous() -> None:
    """As u -> 0 the arc tends to the straight segment, smoothly across the straight-line branch.

    The arc formula ``(v/u) (sin(th + u dt) - sin th)`` cancels catastrophically for tiny ``u dt``
    (error ~ eps * v / u); the step must stay within rounding of the exact chord
    ``v dt sinc(u dt / 2)`` on both sides of the implementation's straight-line threshold.
    """
    worst = (0.0, "")
    for theta in (0.0, 0.3, 1.2, -2.5, math.pi):
        for v_dt in (0.07, 1.0, 10.0):
            s0 = np.array([1.0, -2.0, theta])
            for dth in (1e-12, 0.5e-9, 0.99e-9, 1.01e-9, 2e-9, 1e-8, 1e-7, 1e-6, 1e-4):
                out = unicycle_step(s0, v_dt, dth, 1.0)
                half = 0.5 * dth
                chord = v_dt * math.sin(half) / half
                exact = s0[:2] + chord * np.array([math.cos(theta + half), math.sin(theta + half)])
                rel = float(np.max(np.abs(out[:2] - exact))) / v_dt
                if rel > worst[0]:
                    worst = (rel, f"theta={theta}, v*dt={v_dt}, u*dt={dth:g}")
    assert worst[0] <= 1e-12, f"relative position error {worst[0]:.3g} at {worst[1]}"


def test_quarter_circle() -> None:
    # v = 1, u = pi/2 for 1 s from the origin heading +x: quarter circle of radius 2/pi
    r = 2.0 / math.pi
    out = unicycle_step(np.array([0.0, 0.0, 0.0]), 1.0, math.pi / 2, 1.0)
    assert out == pytest.approx([r, r, math.pi / 2], abs=1e-12)
    out = unicycle_step(np.array([0.0, 0.0, 0.0]), 1.0, -math.pi / 2, 1.0)
    assert out == pytest.approx([r, -r, -math.pi / 2], abs=1e-12)


def test_pure_rotation_and_heading_wrap() -> None:
    out = unicycle_step(np.array([2.0, 3.0, 3.0]), 0.0, 1.0, 1.0)
    assert out[:2] == pytest.approx([2.0, 3.0], abs=1e-15)
    assert out[2] == pytest.approx(4.0 - 2 * math.pi)


def test_step_does_not_mutate_input() -> None:
    s0 = np.array([1.0, 2.0, 0.5])
    unicycle_step(s0, 1.0, 0.3, 0.1)
    assert s0.tolist() == [1.0, 2.0, 0.5]


@settings(max_examples=200, deadline=None)
@given(st.floats(-5, 5), st.floats(-5, 5))
def test_command_limits(v: float, u: float) -> None:
    spec = UnicycleSpec(v_max=0.707, u_max=1.414)
    cmd = UnicycleCommand(v, u)
    tol = 1e-9  # the documented tolerance of ``violates``
    inside = -tol <= v <= spec.v_max + tol and abs(u) <= spec.u_max + tol
    assert cmd.violates(spec) == (not inside)
    c = cmd.clipped(spec)
    assert not c.violates(spec)
    if 0.0 <= v <= spec.v_max and abs(u) <= spec.u_max:
        assert (c.v, c.u) == (v, u)


def test_clipped_nan_is_zero() -> None:
    c = UnicycleCommand(math.nan, math.inf).clipped(UnicycleSpec(1.0, 1.0))
    assert (c.v, c.u) == (0.0, 0.0)


@settings(max_examples=300, deadline=None)
@given(pose, speed, rate | st.just(0.0) | st.floats(-1e-12, 1e-12), step)
def test_float_path_equals_array_path_and_numpy_sinc(
    p: tuple[float, float, float], v: float, u: float, dt: float
) -> None:
    """``unicycle_advance`` (the simulator's float path) is ``unicycle_step`` bit for bit, and
    both keep numpy's ``sinc`` numbers."""
    out = unicycle_advance(*p, v, u, dt)
    assert np.array_equal(np.array(out), unicycle_step(np.array(p), v, u, dt))
    half = 0.5 * u * dt
    chord = v * dt * float(np.sinc(half / math.pi))
    assert out[0] == p[0] + chord * math.cos(p[2] + half)
    assert out[1] == p[1] + chord * math.sin(p[2] + half)


@settings(max_examples=200, deadline=None)
@given(
    st.floats(allow_nan=True, allow_infinity=True), st.floats(allow_nan=True, allow_infinity=True)
)
def test_clipped_equals_numpy_clip(v: float, u: float) -> None:
    spec = UnicycleSpec(0.7, 1.4)
    c = UnicycleCommand(v, u).clipped(spec)
    ev = 0.0 if not np.isfinite(v) else float(np.clip(v, 0.0, spec.v_max))
    eu = 0.0 if not np.isfinite(u) else float(np.clip(u, -spec.u_max, spec.u_max))
    assert (c.v, c.u) == (ev, eu)
    assert isinstance(c.v, float) and isinstance(c.u, float)
    # numpy scalars (a law's arithmetic) come back as Python floats, within the limits or not
    n = UnicycleCommand(np.float64(v), np.float64(u)).clipped(spec)
    assert (n.v, n.u) == (ev, eu)
    assert type(n.v) is float and type(n.u) is float


@given(pose, speed, st.floats(-math.pi, math.pi), step)
def test_turn_then_move_turns_first_then_goes_straight(
    p: tuple[float, float, float], v: float, turn: float, dt: float
) -> None:
    x, y, th = turn_then_move(*p, v, turn, dt)
    assert abs(math.remainder(th - (p[2] + turn), 2 * math.pi)) < 1e-12
    # a straight move of v dt along the new heading
    assert x - p[0] == pytest.approx(v * dt * math.cos(th), abs=1e-9)
    assert y - p[1] == pytest.approx(v * dt * math.sin(th), abs=1e-9)


def test_an_unknown_kinematics_is_refused() -> None:
    with pytest.raises(ValueError, match="kinematics must be one of arc, turn-then-move"):
        UnicycleSpec(1.0, 1.0, kinematics="skid")


@given(
    st.lists(st.tuples(st.floats(0.0, 2.0), st.floats(-2.0, 2.0)), min_size=1, max_size=30),
    st.floats(0.1, 5.0), st.floats(0.1, 10.0), st.sampled_from([0.01, 0.05, 0.1]),
)  # fmt: skip
def test_an_acceleration_limited_unicycle_changes_its_velocity_by_at_most_its_limits(
    commands: list[tuple[float, float]], accel: float, turn_accel: float, dt: float
) -> None:
    spec = UnicycleSpec(2.0, 2.0, 0.1, accel_max=accel, turn_accel_max=turn_accel)
    body = Unicycle(spec)
    x = y = th = 0.0
    v0 = u0 = 0.0
    for v, u in commands:
        body.hold(UnicycleCommand(v, u))
        for _ in range(3):
            path, _ = body.travel(dt)
            nx, ny, th, turn, _ = body.move(x, y, th, dt, False, 3 * dt)
            v1 = body.speed()
            assert abs(v1 - v0) <= accel * dt + 1e-12
            assert abs(body.turn_rate() - u0) <= turn_accel * dt + 1e-12
            assert turn == pytest.approx(abs(body.turn_rate()) * dt)
            assert math.hypot(nx - x, ny - y) <= path + 1e-12  # the chord of the arc travelled
            x, y, v0, u0 = nx, ny, v1, body.turn_rate()
    # held long enough, it reaches the command
    body.hold(UnicycleCommand(1.5, -1.0))
    for _ in range(int(4.0 / min(accel, turn_accel) / dt) + 2):  # (changes of at most 3)
        body.move(0.0, 0.0, 0.0, dt, False, dt)
    assert body.speed() == pytest.approx(1.5) and body.turn_rate() == pytest.approx(-1.0)


def test_an_ideal_unicycle_takes_the_command_at_once() -> None:
    body = Unicycle(UnicycleSpec(1.0, 1.0))
    body.hold(UnicycleCommand(0.7, 0.3))
    assert body.speed() == 0.7 and body.velocity(0.0) == (0.7, 0.0)
    with pytest.raises(ValueError, match="accel_max must be > 0"):
        UnicycleSpec(1.0, 1.0, accel_max=0.0)


@given(st.floats(-2.0, 2.0), st.floats(-2.0, 2.0), st.floats(0.5, 10.0))
def test_a_limited_turn_then_move_turns_as_the_arc_whatever_the_step(
    u0: float, u_cmd: float, turn_accel: float
) -> None:
    """The period's turn, taken at the decision, is the heading the ramped turn rate gives the
    arc vehicle by the period's end, at any integration step (not one step's ramp times T)."""
    period = 0.25
    ends = []
    for kinematics, n in (("turn-then-move", 1), ("turn-then-move", 5), ("turn-then-move", 25),
                          ("arc", 200)):  # fmt: skip
        body = Unicycle(UnicycleSpec(1.0, 3.0, 0.3, kinematics=kinematics, accel_max=1.0,
                                     turn_accel_max=turn_accel))  # fmt: skip
        body._u = u0  # the turn rate it has
        body.hold(UnicycleCommand(0.5, u_cmd))
        th = 0.0
        for k in range(n):
            _, _, th, _, _ = body.move(0.0, 0.0, th, period / n, k == 0, period)
        ends.append(th)
    assert ends[0] == pytest.approx(ends[1], abs=1e-12) == pytest.approx(ends[2], abs=1e-12)
    # the arc steps at the rate each step reached: a staircase above the ramp by B dt T / 2
    assert ends[0] == pytest.approx(ends[3], abs=1e-12 + turn_accel * (period / 200) * period)
