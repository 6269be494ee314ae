"""Obstacle motion models: bounds (thesis (2.6)-(2.7)), determinism, scripted paths and replay."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.obstacles.motion import (
    ConstantVelocity,
    ObstacleState,
    RandomTurn,
    Replay,
    Waypoints,
    uniform_draw,
)


def _run(model: object, state: ObstacleState, n: int, dt: float) -> list[ObstacleState]:
    out = [state]
    for i in range(n):
        state = model.step(state, i * dt, dt)  # type: ignore[attr-defined]
        out.append(state)
    return out


def test_constant_velocity_translates_and_spins() -> None:
    m = ConstantVelocity(velocity=np.array([0.3, -0.1]), angular_velocity=0.2)
    states = _run(m, ObstacleState(position=np.array([1.0, 2.0]), heading=0.5), 50, 0.1)
    assert states[-1].position == pytest.approx([1.0 + 1.5, 2.0 - 0.5])
    assert states[-1].heading == pytest.approx(0.5 + 1.0)
    assert states[-1].velocity == pytest.approx([0.3, -0.1])
    assert states[-1].angular_velocity == 0.2
    assert m.speed_bound() == pytest.approx(math.hypot(0.3, 0.1))
    assert m.turn_bound() == 0.2


@settings(max_examples=25, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.tuples(st.floats(0.0, 1.0), st.floats(0.0, 1.0)).map(sorted),
    st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)).map(sorted),
    st.floats(-0.5, 0.5),
    st.sampled_from([0.05, 0.1, 0.3]),
)
def test_random_turn_respects_bounds(
    seed: int, speed: list[float], turn: list[float], spin: float, dt: float
) -> None:
    m = RandomTurn(
        speed=tuple(speed), turn_rate=tuple(turn), rng=np.random.default_rng(seed), spin=spin
    )  # type: ignore[arg-type]
    states = _run(m, ObstacleState(position=np.zeros(2)), 100, dt)
    for prev, st_ in itertools.pairwise(states):
        v = float(np.hypot(*st_.velocity))
        assert speed[0] - 1e-12 <= v <= speed[1] + 1e-12
        assert v <= m.speed_bound() + 1e-12
        course_rate = st_.angular_velocity - spin
        assert turn[0] - 1e-12 <= course_rate <= turn[1] + 1e-12
        assert abs(st_.angular_velocity) <= m.turn_bound() + 1e-12
        # the state is advanced with the rates it reports
        assert st_.position == pytest.approx(prev.position + st_.velocity * dt, abs=1e-12)
        assert math.remainder(
            st_.heading - prev.heading - st_.angular_velocity * dt, 2 * math.pi
        ) == pytest.approx(0.0, abs=1e-12)


def test_random_turn_draws_every_change_period() -> None:
    m = RandomTurn(
        speed=(0.1, 0.4), turn_rate=(-0.3, 0.3), rng=np.random.default_rng(3), change_period=1.0
    )
    states = _run(m, ObstacleState(position=np.zeros(2)), 40, 0.1)
    speeds = np.round([np.hypot(*s.velocity) for s in states[1:]], 12)
    # constant within each 1 s window (10 steps), changes between windows
    for w in range(4):
        assert len(set(speeds[10 * w : 10 * w + 10])) == 1
    assert len(set(speeds)) == 4


def test_random_turn_is_deterministic_given_seed() -> None:
    def traj(seed: int) -> np.ndarray:
        m = RandomTurn(
            speed=(0.1, 0.4), turn_rate=(-0.3, 0.3), rng=np.random.default_rng(seed), spin=0.1
        )
        states = _run(m, ObstacleState(position=np.array([5.0, 5.5])), 300, 0.1)
        return np.array([[*s.position, s.heading, *s.velocity, s.angular_velocity] for s in states])

    a, b, c = traj(7), traj(7), traj(8)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_random_turn_returns_to_arena() -> None:
    arena = (0.0, 0.0, 10.0, 10.0)
    m = RandomTurn(
        speed=(0.3, 0.4), turn_rate=(-0.5, 0.5), rng=np.random.default_rng(0), arena=arena
    )
    # starts outside, heading away from the arena
    state = ObstacleState(position=np.array([-3.0, 5.0]), heading=math.pi)
    states = _run(m, state, 400, 0.1)
    inside = [0 <= s.position[0] <= 10 and 0 <= s.position[1] <= 10 for s in states]
    assert any(inside)
    first = inside.index(True)
    # once back, it never strays more than a turning circle's diameter outside
    for s in states[first:]:
        assert -2 * 0.4 / 0.5 - 0.1 <= s.position[0] <= 10 + 2 * 0.4 / 0.5 + 0.1
        assert -2 * 0.4 / 0.5 - 0.1 <= s.position[1] <= 10 + 2 * 0.4 / 0.5 + 0.1
        assert abs(s.angular_velocity) <= 0.5 + 1e-12


def test_waypoints_visits_every_waypoint_and_stops() -> None:
    pts = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    m = Waypoints(points=pts, speed=0.25)
    dt = 0.1
    states = _run(m, ObstacleState(position=np.zeros(2)), 200, dt)
    pos = np.array([s.position for s in states])
    # the path is the polyline: every sample lies on it, and the samples reach each waypoint
    for w in pts:
        assert np.min(np.hypot(*(pos - w).T)) <= 0.25 * dt + 1e-12
    assert states[-1].position == pytest.approx(pts[-1], abs=1e-12)
    assert np.allclose(states[-1].velocity, 0.0)
    # total time: 3 m at 0.25 m/s -> arrives at 12 s and stays
    arrived = next(i for i, s in enumerate(states) if np.allclose(s.position, pts[-1], atol=1e-12))
    assert arrived * dt == pytest.approx(12.0, abs=dt + 1e-9)
    for s in states[1:]:
        assert np.hypot(*s.velocity) <= 0.25 + 1e-12


def test_waypoints_loop_and_heading_follow_course() -> None:
    pts = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    m = Waypoints(points=pts, speed=0.5, loop=True)
    states = _run(m, ObstacleState(position=np.zeros(2)), 200, 0.1)
    # one loop takes 8 s; after 20 s it is still moving, at exactly 0.5 m/s along a side
    assert np.hypot(*states[-1].velocity) == pytest.approx(0.5)
    assert states[5].heading == pytest.approx(0.0)  # along +x
    assert states[25].heading == pytest.approx(math.pi / 2)  # along +y


def test_waypoints_without_turning_keeps_heading() -> None:
    m = Waypoints(points=np.array([[0.0, 1.0]]), speed=1.0, turn_with_course=False)
    states = _run(m, ObstacleState(position=np.zeros(2), heading=0.3), 20, 0.1)
    assert all(s.heading == 0.3 and s.angular_velocity == 0.0 for s in states[1:])
    assert m.turn_bound() == 0.0


def test_replay_interpolates_and_holds() -> None:
    times = np.array([0.0, 1.0, 3.0])
    positions = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 4.0]])
    m = Replay(times=times, positions=positions)
    assert m.position_at(0.5) == pytest.approx([0.5, 0.0])
    assert m.position_at(2.0) == pytest.approx([1.0, 2.0])
    assert m.position_at(-1.0) == pytest.approx([0.0, 0.0])
    assert m.position_at(10.0) == pytest.approx([1.0, 4.0])
    dt = 0.1
    states = _run(m, ObstacleState(position=np.zeros(2)), 40, dt)
    for i, s in enumerate(states):
        assert s.position == pytest.approx(m.position_at(i * dt), abs=1e-12)
    assert states[5].velocity == pytest.approx([1.0, 0.0])  # inside the first segment
    assert states[20].velocity == pytest.approx([0.0, 2.0])  # inside the second
    assert states[20].heading == pytest.approx(math.pi / 2)
    assert states[40].velocity == pytest.approx([0.0, 0.0], abs=1e-12)  # held after the last sample
    assert m.speed_bound() == pytest.approx(2.0)


@settings(max_examples=50, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.tuples(st.floats(-5.0, 5.0), st.floats(-5.0, 5.0)),
)
def test_uniform_draw_is_generator_uniform(seed: int, bounds: tuple[float, float]) -> None:
    """RandomTurn draws with ``lo + (hi - lo) * random()``: numpy's own formula for
    ``Generator.uniform``, so the numbers and the stream are those of ``rng.uniform(lo, hi)``."""
    a = np.random.default_rng(seed)
    b = np.random.default_rng(seed)
    if bounds[1] < bounds[0]:
        with pytest.raises(ValueError):
            b.uniform(*bounds)
        with pytest.raises(ValueError):
            uniform_draw(a, bounds)
        return
    for _ in range(20):
        assert uniform_draw(a, bounds) == float(b.uniform(*bounds))
    assert a.random() == b.random()  # same stream position afterwards
