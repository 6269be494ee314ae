"""ObstacleBatch: the simulator's vectorised obstacle motion equals the per-obstacle ``step``
reference bit for bit (draws, arena steering, angle wrapping, write-back)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from uvnav.geometry.angles import wrap_scalar
from uvnav.obstacles import (
    ConstantVelocity,
    DiscBody,
    FieldTemplate,
    Obstacle,
    ObstacleBatch,
    ObstacleField,
    ObstacleState,
    PolygonBody,
    RandomTurn,
    Replay,
    Waypoints,
)
from uvnav.obstacles.batch import wrap_array, wrap_array_inplace

ARROW = np.array([[-0.6, -0.4], [0.7, -0.5], [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]])


class Spiral(RandomTurn):
    """A subclass: the batch must call its own ``step``, not the vectorised RandomTurn path."""

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState:
        out = super().step(state, t, dt)
        return ObstacleState(
            position=out.position * 1.001,
            heading=out.heading,
            velocity=out.velocity,
            angular_velocity=out.angular_velocity,
        )


def _world(seed: int, k: int, *, arena_size: float = 6.0, kinds: str = "mixed") -> list[Obstacle]:
    """``k`` obstacles with every kind of motion; random-turn ones in small arenas (often out)."""
    rng = np.random.default_rng(seed)
    obs = []
    for j in range(k):
        body = DiscBody(0.3) if j % 3 == 1 else PolygonBody.from_vertices(ARROW)
        pos = rng.uniform(-8.0, 8.0, 2)
        state = ObstacleState(
            position=pos,
            heading=float(rng.uniform(-math.pi, math.pi)),
            velocity=rng.normal(size=2) * (j % 2),
            angular_velocity=float(rng.normal()),
        )
        kind = "rt" if kinds == "rt" else ("rt", "rt", "cv", "wp", "rp", "sub", "rt-open")[j % 7]
        motion: object
        if kind in ("rt", "rt-open"):
            lo = rng.uniform(-arena_size, 0.0, 2)
            arena = (lo[0], lo[1], lo[0] + arena_size, lo[1] + arena_size)
            motion = RandomTurn(
                speed=(0.1, float(rng.uniform(0.2, 0.8))),
                turn_rate=(-0.6, float(rng.uniform(0.1, 0.6))),
                rng=rng.spawn(1)[0],
                change_period=float(rng.choice([0.3, 1.0, 1.7])),
                spin=float(rng.uniform(-0.5, 0.5)),
                arena=arena if kind == "rt" else None,
                course=None if j % 2 else float(rng.uniform(-4.0, 4.0)),
            )
        elif kind == "cv":
            motion = ConstantVelocity(rng.normal(size=2), float(rng.normal()))
        elif kind == "wp":
            motion = Waypoints(points=rng.uniform(-5, 5, (3, 2)), speed=0.7, loop=True)
        elif kind == "rp":
            times = np.cumsum(rng.uniform(0.5, 2.0, 5))
            motion = Replay(times=times, positions=rng.uniform(-5, 5, (5, 2)))
        else:
            motion = Spiral(speed=(0.1, 0.3), turn_rate=(-0.2, 0.2), rng=rng.spawn(1)[0])
        obs.append(Obstacle(body, state, motion))  # type: ignore[arg-type]
    return obs


def _reference(obstacles: list[Obstacle], n: int, dt: float) -> list[list[ObstacleState]]:
    """States after every step of the per-obstacle loop the simulator used to run."""
    out = []
    for i in range(n):
        for ob in obstacles:
            ob.state = ob.motion.step(ob.state, i * dt, dt)
        out.append([ob.state for ob in obstacles])
    return out


def _same_state(a: ObstacleState, b: ObstacleState) -> bool:
    return (
        np.array_equal(np.asarray(a.position), np.asarray(b.position))
        and a.heading == b.heading
        and np.array_equal(np.asarray(a.velocity), np.asarray(b.velocity))
        and a.angular_velocity == b.angular_velocity
    )


def _check_equal(seed: int, k: int, n: int, dt: float, **kw: object) -> ObstacleBatch:
    ref_world = _world(seed, k, **kw)  # type: ignore[arg-type]
    world = copy.deepcopy(ref_world)
    ref = _reference(ref_world, n, dt)
    batch = ObstacleBatch(world)
    tpl = FieldTemplate.from_bodies([o.body for o in world])
    for i in range(n):
        batch.step(i * dt, dt)
        fld = batch.field(tpl)
        expect = ObstacleField.from_obstacles(
            [Obstacle(o.body, s, o.motion) for o, s in zip(ref_world, ref[i], strict=True)], tpl
        )
        for name in ("centres", "headings", "velocities", "angular_velocities"):
            assert np.array_equal(getattr(fld, name), getattr(expect, name)), (name, i)
        for j in range(k):
            assert _same_state(batch.state(j), ref[i][j]), (i, j)
    batch.write_back()
    for ob, rob in zip(world, ref_world, strict=True):
        assert _same_state(ob.state, rob.state)
        if isinstance(rob.motion, RandomTurn):
            for attr in ("course", "_speed", "_turn", "_next_change"):
                assert getattr(ob.motion, attr) == getattr(rob.motion, attr), attr
    return batch


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 15), st.sampled_from([0.05, 0.1, 0.25]))
@example(seed=0, k=14, dt=0.1)
def test_batch_equals_per_obstacle_step_bit_for_bit(seed: int, k: int, dt: float) -> None:
    _check_equal(seed, k, 120, dt)


@pytest.mark.parametrize("k", [3, 40])
def test_many_random_turns_outside_their_arenas(k: int) -> None:
    """Tiny arenas: most obstacles are outside at once (the array steering path) or a few are
    (the one-by-one path); both must equal the reference."""
    _check_equal(7, k, 200, 0.1, arena_size=0.5, kinds="rt")


def test_continuing_after_write_back_matches() -> None:
    """The written-back states and model internals let the per-obstacle loop carry on exactly."""
    ref_world = _world(5, 9)
    world = copy.deepcopy(ref_world)
    _reference(ref_world, 60, 0.1)
    batch = ObstacleBatch(world)
    for i in range(30):
        batch.step(i * 0.1, 0.1)
    batch.write_back()
    batch2 = ObstacleBatch(world)
    for i in range(30, 60):
        batch2.step(i * 0.1, 0.1)
    batch2.write_back()
    for ob, rob in zip(world, ref_world, strict=True):
        assert _same_state(ob.state, rob.state)


def test_batch_arrays_are_snapshots() -> None:
    world = _world(2, 8)
    batch = ObstacleBatch(world)
    tpl = FieldTemplate.from_bodies([o.body for o in world])
    batch.step(0.0, 0.1)
    fld = batch.field(tpl)
    before = [a.copy() for a in (fld.centres, fld.headings, fld.velocities)]
    batch.step(0.1, 0.1)
    for a, b in zip(before, (fld.centres, fld.headings, fld.velocities), strict=True):
        assert np.array_equal(a, b)


def test_empty_and_unstepped_batch() -> None:
    batch = ObstacleBatch([])
    batch.step(0.0, 0.1)
    assert len(batch) == 0 and batch.positions.shape == (0, 2)
    world = _world(1, 3)
    states = [ob.state for ob in world]
    ObstacleBatch(world).write_back()  # nothing stepped: states untouched
    assert all(ob.state is s for ob, s in zip(world, states, strict=True))


angles = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6)


@settings(max_examples=200, deadline=None)
@given(st.lists(angles | st.sampled_from([math.pi, -math.pi, 3 * math.pi, 0.0, -0.0]), max_size=9))
def test_array_wraps_equal_wrap_scalar(values: list[float]) -> None:
    a = np.array(values, dtype=float)
    expect = [wrap_scalar(v) for v in values]
    got_inplace = wrap_array_inplace(a.copy())
    got_array = wrap_array(a)
    for e, x, y in zip(expect, got_inplace.tolist(), got_array.tolist(), strict=True):
        assert math.copysign(1.0, e) == math.copysign(1.0, x) and e == x
        assert math.copysign(1.0, e) == math.copysign(1.0, y) and e == y


def test_array_wraps_nan_like_wrap_scalar() -> None:
    a = np.array([math.nan, 1.0])
    assert wrap_array_inplace(a.copy())[0] == wrap_scalar(math.nan)
    assert wrap_array(a)[0] == wrap_scalar(math.nan)
