"""Packed worlds (uvnav.sim.packed) against the loop world they reproduce, bit for bit."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from uvnav.controllers.base import make_law
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec
from uvnav.geometry.kernels3d import numba_available, use_compiled
from uvnav.geometry.small import pyhypot
from uvnav.obstacles import Obstacle, ObstacleField, ObstacleState
from uvnav.obstacles.bodies import DiscBody, PolygonBody
from uvnav.obstacles.motion import ConstantVelocity, RandomTurn, Waypoints
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.loader import load_scenario
from uvnav.sensors.exact import beam_turns, lidar_scan
from uvnav.sensors.observation import Readings, read_arrays
from uvnav.sim.bodies2d import FieldBodies, PackedBodies
from uvnav.sim.episode import World2D
from uvnav.sim.packed import (
    BLOCK,
    STATUS_NAMES,
    PackedWorlds,
    direct,
    kernel,
    pack_check,
    reseed_spawned,
)
from uvnav.sim.run import run_episode
from uvnav.sim.seeding import run_rng, world_rng
from uvnav.sim.setup import EpisodeResult, EpisodeSetup

REL = np.linspace(-np.pi, np.pi, 16, endpoint=False)
SPEC = UnicycleSpec(v_max=0.8, u_max=1.2, radius=0.2)
SQUARE = np.array([[-0.4, -0.3], [0.4, -0.3], [0.4, 0.3], [-0.4, 0.3]])


@contextmanager
def kernels(compiled: bool) -> Iterator[None]:
    if compiled and not numba_available():
        pytest.skip("needs numba (the fast extra)")
    previous = use_compiled(compiled)
    try:
        yield
    finally:
        use_compiled(previous)


finite = st.floats(-1e300, 1e300, allow_nan=False)


@given(finite, finite)
@example(3.0, 4.0)
@example(1e-310, 3e-320)
@example(0.0, -0.0)
@example(1e300, 1e300)
@example(math.inf, math.nan)
@example(math.nan, 1.0)
def test_pyhypot_is_cpythons_hypot(x: float, y: float) -> None:
    want = math.hypot(x, y)
    got = pyhypot(x, y)
    assert got == want or (math.isnan(got) and math.isnan(want))


def mixed_setup(seed: int, n: int = 12, t_max: float = 30.0) -> EpisodeSetup:
    """Random-turn polygons in an arena (some outside it, some spinning) and constant-velocity
    ones, around a robot crossing them."""
    rng = np.random.default_rng(seed)
    obstacles = []
    for j in range(n):
        pos = rng.uniform(-1.0, 9.0, 2)
        body = PolygonBody.from_vertices(SQUARE * rng.uniform(0.5, 1.5))
        state = ObstacleState(position=pos, heading=float(rng.uniform(-3, 3)))
        motion: ConstantVelocity | RandomTurn
        if j % 3 == 0:
            motion = ConstantVelocity(rng.uniform(-0.3, 0.3, 2), float(rng.uniform(-0.5, 0.5)))
        else:
            motion = RandomTurn(speed=(0.1, 0.5), turn_rate=(-0.4, 0.4), rng=rng.spawn(1)[0],
                                change_period=float(rng.uniform(0.3, 2.0)),
                                spin=0.1 * (j % 2), arena=(1.0, 1.0, 7.0, 7.0))  # fmt: skip
        obstacles.append(Obstacle(body, state, motion))
    return EpisodeSetup(spec=SPEC, start=np.array([-2.0, -2.0, 0.7]), goal=np.array([10.0, 9.0]),
                        obstacles=obstacles, dt=0.05, control_period=0.15, t_max=t_max)  # fmt: skip


def run_both(make: object, seed: int, max_decisions: int = 10**6) -> tuple[str, int]:
    """Drive the loop world and a packed world with the same random commands; every decision
    the pose, clearance, status and lidar must be equal.  Returns (status, decisions)."""
    ref = World2D(make(), run_rng(seed), exact=True)  # type: ignore[operator]
    ref.start([False])
    packed = PackedWorlds(1)
    packed.load(0, make())  # type: ignore[operator]
    rng = np.random.default_rng(seed)
    ranges, out, dist = (
        np.empty((1, len(REL))),
        np.empty((1, 4 + len(REL)), np.float32),
        np.empty(1),
    )
    n = 0
    while not ref.done and n < max_decisions:
        v, u = rng.uniform(-0.1, 1.1) * SPEC.v_max, rng.uniform(-1.1, 1.1) * SPEC.u_max
        cmd = ref.apply(UnicycleCommand(v, u))
        packed.command[0] = (cmd.v, cmd.u)
        while True:
            ref.advance()
            if ref.done or ref.acting():
                break
        packed.step()
        n += 1
        assert tuple(packed.robot[0]) == tuple(ref.pose)
        assert packed.clearance[0] == ref.clearance
        status = STATUS_NAMES[packed.status[0]]
        assert status == (ref.status if ref.done else "running")
        packed.observe(REL, 3.0, 10.0, ranges, out, dist)
        scan = lidar_scan(ref.pose, ref.field, n_rays=len(REL), max_range=3.0).ranges
        assert np.array_equal(ranges[0], scan)
        assert dist[0] == math.hypot(*(ref.goal - ref.pose[:2]))
    return ref.status, n


@pytest.mark.parametrize("compiled", [True, False])
def test_packed_equals_the_loop_world_on_random_ch2(compiled: bool) -> None:
    with kernels(compiled):
        for seed in range(3 if compiled else 1):
            scene = load_scenario(f"random-ch2:{seed}")
            run_both(lambda s=seed, sc=scene: build_episode(sc, s), seed)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_packed_equals_the_loop_world_with_arenas_spin_and_constant_motion(seed: int) -> None:
    with kernels(numba_available()):
        run_both(lambda: mixed_setup(seed), seed)


def test_pre_drawn_numbers_are_the_generators_stream_across_refills() -> None:
    def far_wanderer() -> EpisodeSetup:
        setup = mixed_setup(9, n=1)
        motion = RandomTurn(speed=(0.1, 0.5), turn_rate=(-1.0, 1.0),
                            rng=np.random.default_rng(4), change_period=0.05)  # fmt: skip
        far = ObstacleState(position=np.array([50.0, 50.0]))
        setup.obstacles[0] = Obstacle(PolygonBody.from_vertices(SQUARE), far, motion)
        return setup

    with kernels(numba_available()):
        _, decisions = run_both(far_wanderer, 0, max_decisions=150)
    assert decisions == 150  # 2 draws per step, 3 steps a decision: 900 numbers, 14 blocks
    assert 6 * decisions > 10 * BLOCK


def test_a_slot_keeps_its_world_when_a_bigger_one_is_loaded_beside_it() -> None:
    with kernels(numba_available()):
        alone = PackedWorlds(1)
        alone.load(0, mixed_setup(5, n=3))
        both = PackedWorlds(2)
        both.load(0, mixed_setup(5, n=3))
        both.step()
        alone.step()
        both.load(1, mixed_setup(6, n=20))  # grows the obstacle arrays
        for _ in range(40):
            alone.step()
            both.step()
        assert np.array_equal(alone.wf[0], both.wf[0])
        assert np.array_equal(alone.state[0], both.state[0, :, :3])


def test_episodes_that_end_at_the_start() -> None:
    base = mixed_setup(0, n=1)
    base.obstacles[0].state = ObstacleState(position=np.array([-2.0, -2.0]))
    packed = PackedWorlds(2)
    packed.load(0, base)
    packed.load(1, EpisodeSetup(spec=SPEC, start=np.array([1.0, 1.0, 0.0]),
                                goal=np.array([1.0, 1.1]), obstacles=[]))  # fmt: skip
    assert [STATUS_NAMES[s] for s in packed.status] == ["collision", "success"]
    with pytest.raises(ValueError, match="t_max must be a whole multiple of dt"):  # no step
        packed.load(1, EpisodeSetup(spec=SPEC, start=np.zeros(3), goal=np.ones(2), obstacles=[],
                                    t_max=0.0))  # fmt: skip
    before = packed.wf.copy()
    packed.step()
    assert np.array_equal(packed.wf[:, :3], before[:, :3])  # nothing moves
    assert np.isinf(packed.low).all()


def test_unpackable_scenes_are_refused_with_the_reason() -> None:
    setup = mixed_setup(0, n=2)
    setup.obstacles[1] = Obstacle(DiscBody(0.3), ObstacleState(position=np.zeros(2)),
                                  ConstantVelocity(np.zeros(2)))  # fmt: skip
    assert pack_check(setup) == "obstacle 1 is a DiscBody, packed worlds hold polygons"
    setup.obstacles[1] = Obstacle(
        PolygonBody.from_vertices(SQUARE),
        ObstacleState(position=np.zeros(2)),
        Waypoints(points=np.ones((2, 2)), speed=0.1),
    )
    with pytest.raises(ValueError, match="obstacle 1 moves by Waypoints"):
        PackedWorlds(1).load(0, setup)
    assert pack_check(mixed_setup(0)) is None
    shared = mixed_setup(0, n=3)
    shared.obstacles[2].motion.rng = shared.obstacles[1].motion.rng  # type: ignore[attr-defined]
    assert pack_check(shared) == (
        "obstacles 1 and 2 draw from one generator, packed worlds pre-draw each obstacle's numbers"
    )


def test_decisions_that_read_more_than_a_row_of_pre_drawn_numbers() -> None:
    def long_decisions() -> EpisodeSetup:
        setup = mixed_setup(9, n=1)
        motion = RandomTurn(speed=(0.1, 0.5), turn_rate=(-1.0, 1.0),
                            rng=np.random.default_rng(4), change_period=0.05)  # fmt: skip
        far = ObstacleState(position=np.array([50.0, 50.0]))
        setup.obstacles[0] = Obstacle(PolygonBody.from_vertices(SQUARE), far, motion)
        setup.control_period = 0.05 * (3 * BLOCK)  # 6 blocks of draws a decision
        return setup

    with kernels(numba_available()):
        _, decisions = run_both(long_decisions, 0, max_decisions=6)
        assert decisions == 4  # 30 s at 9.6 s a decision

        alone = PackedWorlds(1)
        alone.load(0, mixed_setup(5, n=3))
        both = PackedWorlds(3)  # slot 2 is never loaded
        both.load(0, mixed_setup(5, n=3))
        for _ in range(30):
            alone.step()
            both.step()
        both.load(1, long_decisions())  # lengthens the rows of pre-drawn numbers
        for _ in range(150):
            alone.step()
            both.step()
        assert np.array_equal(alone.wf[0], both.wf[0])
        assert np.array_equal(alone.state[0], both.state[0, :, :3])


@pytest.mark.parametrize("compiled", [True, False])
def test_a_loaded_worlds_clearance_is_the_fields_at_the_start(compiled: bool) -> None:
    """A world loaded with the robot in, on or near a body starts with the field's clearance,
    bit for bit, and a robot that overlaps one starts collided."""
    rng = np.random.default_rng(5)
    obstacles = [
        Obstacle(
            PolygonBody.from_vertices(SQUARE * s),
            ObstacleState(position=p, heading=h),
            ConstantVelocity(np.zeros(2)),
        )
        for s, p, h in ((1.0, np.array([0.0, 0.0]), 0.4), (0.7, np.array([1.1, 0.3]), -1.0))
    ]
    field = ObstacleField.from_obstacles(obstacles)
    starts = rng.uniform(-1.2, 2.2, (300, 2))
    with kernels(compiled):
        worlds = PackedWorlds(len(starts))
        for slot, (x, y) in enumerate(starts):
            worlds.load(slot, EpisodeSetup(spec=SPEC, start=np.array([x, y, 0.0]),
                                           goal=np.array([9.0, 9.0]), obstacles=obstacles,
                                           dt=0.1, control_period=0.1))  # fmt: skip
    collided = 0
    for slot, (x, y) in enumerate(starts):
        want = float((field.query((x, y), 0.0, nearest=True).signed - SPEC.radius).min())
        assert worlds.clearance[slot] == want
        collided += STATUS_NAMES[int(worlds.status[slot])] == "collision"
        assert (STATUS_NAMES[int(worlds.status[slot])] == "collision") == (want < 0)
    assert 30 < collided < 270


@pytest.mark.parametrize("compiled", [True, False])
def test_a_direct_kernel_gives_what_the_kernel_gives(compiled: bool) -> None:
    """:func:`direct` returns the kernel's result and a function that skips numba's dispatch
    (the kernel itself on the Python path) giving the same numbers for other values."""
    body = PolygonBody.from_vertices(SQUARE)
    still = ConstantVelocity(np.zeros(2))
    obstacles = [Obstacle(body, ObstacleState(position=np.zeros(2)), still)]
    with kernels(compiled):
        worlds = PackedWorlds(1)
        worlds.load(0, EpisodeSetup(spec=SPEC, start=np.array([3.0, 0.0, 0.0]),
                                    goal=np.array([9.0, 9.0]), obstacles=obstacles, dt=0.1,
                                    control_period=0.1))  # fmt: skip
        fn = kernel("clearance_one")
        arrays = (worlds.params[0], worlds.state[0], worlds.rings[0])
        out, fast = direct(fn, 3.0, 0.0, 0.2, 1, *arrays)
        assert out == fn(3.0, 0.0, 0.2, 1, *arrays)
        assert (fast is fn) is not compiled
        for x, y in ((1.0, 0.5), (-2.0, 0.25), (0.1, 0.0)):
            assert fast(x, y, 0.2, 1, *arrays) == fn(x, y, 0.2, 1, *arrays)
    assert out[0] == pytest.approx(3.0 - 0.4 - 0.2)


@pytest.mark.parametrize("compiled", [True, False])
def test_clearance_inside_a_body_is_the_fields_signed_distance(compiled: bool) -> None:
    """Robots driven one step into (and near) static bodies: the clearance is the field's,
    bit for bit, depth inside a body included (numpy's hypot, not CPython's)."""
    rng = np.random.default_rng(3)
    arrow = np.array([[-0.6, -0.4], [0.7, 0.0], [-0.6, 0.4], [-0.2, 0.0]])
    shapes = (
        (SQUARE, np.array([1.0, 0.5]), 0.3),
        (arrow * 1.5, np.array([-0.5, 0.0]), 2.0),
        (SQUARE * 0.6, np.array([0.2, -1.0]), -1.0),
    )
    obstacles = [
        Obstacle(
            PolygonBody.from_vertices(v),
            ObstacleState(position=p, heading=h),
            ConstantVelocity(np.zeros(2)),
        )
        for v, p, h in shapes
    ]
    field = ObstacleField.from_obstacles(obstacles)
    k = 1500
    with kernels(compiled):
        worlds = PackedWorlds(k)
        for slot in range(k):
            worlds.load(slot, EpisodeSetup(spec=SPEC, start=np.array([0.0, 3.0, 0.0]),
                                           goal=np.array([9.0, 9.0]), obstacles=obstacles,
                                           dt=0.1, control_period=0.1))  # fmt: skip
        centres = np.array([ob.state.position for ob in obstacles])
        aim = centres[rng.integers(0, 3, k)] + rng.normal(0.0, 0.4, (k, 2)) - (0.0, 3.0)
        worlds.robot[:, 2] = np.arctan2(aim[:, 1], aim[:, 0])
        worlds.command[:, 0] = np.hypot(aim[:, 0], aim[:, 1]) / 0.1
        worlds.step()
    inside = 0
    for slot in range(k):
        q = field.query(tuple(worlds.robot[slot, :2]), 0.0, nearest=True)
        assert worlds.clearance[slot] == float((q.signed - SPEC.radius).min())
        inside += bool(q.signed.min() < 0)
    assert inside > k // 3


def episode(make: Callable[[], EpisodeSetup], law: str, seed: int, *, compiled: bool,
            record: bool) -> tuple[EpisodeResult, list[tuple[object, ...]]]:  # fmt: skip
    """One :func:`run_episode`; its result and what it left on the obstacles and their
    models (states, draws, course, and the generator's next number)."""
    vehicle = "holonomic" if "holonomic" in law else "unicycle"
    setup = make()
    result = run_episode(setup, make_law(law, vehicle=vehicle), run_rng(seed), record=record,
                         compiled=compiled, vehicle=vehicle)  # fmt: skip
    left = []
    for ob in setup.obstacles:
        mod, st = ob.motion, ob.state
        extra = (
            (mod.course, mod._speed, mod._turn, mod._next_change, mod.rng.random())
            if isinstance(mod, RandomTurn)
            else ()
        )
        left.append((*st.position, st.heading, *st.velocity, st.angular_velocity, *extra))
    return result, left


def same_result(a: EpisodeResult, b: EpisodeResult) -> None:
    assert a.status == b.status
    ma, mb = a.metrics.to_dict(), b.metrics.to_dict()
    timed = {k for k in ma if "decision" in k}
    assert {k: v for k, v in ma.items() if k not in timed} == {
        k: v for k, v in mb.items() if k not in timed
    }
    if a.trajectory is not None:
        assert b.trajectory is not None
        for f in dataclasses.fields(a.trajectory):
            va, vb = getattr(a.trajectory, f.name), getattr(b.trajectory, f.name)
            if f.name == "obstacle_shapes":
                assert all(np.array_equal(x, y) for x, y in zip(va, vb, strict=True))
            elif isinstance(va, np.ndarray):
                assert np.array_equal(va, vb, equal_nan=True), f.name
            else:
                assert va == vb, f.name


LAWS = ("zhang2019-v1", "savkin-wang2013-v1")
CASES = [
    *[(f"random-ch2:{s}", law) for s in (0, 1, 2, 5) for law in LAWS],
    *[(f"mixed:{s}", "zhang2019-v1") for s in (0, 1)],
    ("random-ch2:3", "zhang2019-v2"),
    ("random-ch2:4", "zhang2019-holonomic-v2"),
    ("mixed:2", "orca-holonomic-v1"),
]


@pytest.mark.parametrize(("scene", "law"), CASES)
@pytest.mark.parametrize("record", [False, True])
def test_the_compiled_episode_path_equals_the_numpy_path(scene: str, law: str,
                                                         record: bool) -> None:  # fmt: skip
    """run_episode with the obstacles packed (PackedBodies) gives the numpy path's episode
    bit for bit: status, metrics, trajectory, and the obstacles and generators it leaves."""
    if not numba_available():
        pytest.skip("needs numba (the fast extra)")
    kind, seed = scene.split(":")
    s = int(seed)

    def make() -> EpisodeSetup:
        if kind == "mixed":
            return mixed_setup(s, t_max=20.0)
        return build_episode(load_scenario(scene), s)

    ref, ref_left = episode(make, law, s, compiled=False, record=record)
    got, got_left = episode(make, law, s, compiled=True, record=record)
    same_result(ref, got)
    assert got_left == ref_left


def test_the_compiled_path_serves_the_scenes_it_can_pack() -> None:
    scene = load_scenario("random-ch2:0")

    def bodies(setup: EpisodeSetup, packed: bool) -> object:
        return World2D(setup, run_rng(0), exact=False, packed=packed).bodies

    assert isinstance(bodies(build_episode(scene, 0), True), PackedBodies)
    assert isinstance(bodies(build_episode(scene, 0), False), FieldBodies)
    setup = mixed_setup(0, n=2)
    setup.obstacles[1] = Obstacle(DiscBody(0.3), ObstacleState(position=np.zeros(2)),
                                  ConstantVelocity(np.zeros(2)))  # fmt: skip
    assert isinstance(bodies(setup, True), FieldBodies)


def test_the_compiled_path_leaves_the_generators_where_the_numpy_path_does_across_top_ups() -> None:
    """Obstacles that redraw every step read past half their row many times: the counts of
    PackedWorlds.refill put each generator back where the lazy draws leave it."""
    if not numba_available():
        pytest.skip("needs numba (the fast extra)")

    def make() -> EpisodeSetup:
        setup = mixed_setup(4, t_max=20.0)
        for ob in setup.obstacles:
            if isinstance(ob.motion, RandomTurn):
                ob.motion.change_period = 0.05  # a new draw every step
        return setup

    ref, ref_left = episode(make, "zhang2019-v1", 4, compiled=False, record=False)
    got, got_left = episode(make, "zhang2019-v1", 4, compiled=True, record=False)
    same_result(ref, got)
    assert got_left == ref_left
    world = World2D(make(), run_rng(4), exact=False, packed=True)
    assert isinstance(world.bodies, PackedBodies)
    for _ in range(200):
        world.bodies.step(0.05 * _, 0.05, 0.0, 0.0, 0.2)
    assert world.bodies._pw.read.max() > 0  # the rows were topped up


@pytest.mark.parametrize("compiled", [False, True])
def test_the_lidar_kernel_is_lidar_scan_near_inside_and_far_from_bodies(compiled: bool) -> None:
    """Poses around every body of a random-ch2 scene (on edges, inside, beyond the range): the
    kernel's ranges equal :func:`lidar_scan`'s, beams in any direction."""
    if compiled and not numba_available():
        pytest.skip("needs numba (the fast extra)")
    setup = build_episode(load_scenario("random-ch2:5"), 3)
    field = ObstacleField.from_obstacles(setup.obstacles)
    worlds = PackedWorlds(1)
    worlds.load(0, setup)
    rng = np.random.default_rng(7)
    rel = np.linspace(-math.pi, math.pi, 90, endpoint=False)
    turns = beam_turns(rel)
    ranges, dirs = np.empty(90), np.empty((2, 90))
    ring = np.empty((2, worlds.rings.shape[3]))
    with kernels(compiled):
        lidar = kernel("lidar")
        for ob in setup.obstacles:
            for _ in range(20):
                x, y = np.asarray(ob.state.position) + rng.normal(0.0, 1.0, 2)
                th = float(rng.uniform(-7.0, 7.0))
                lidar(float(x), float(y), th, turns, 4.0, len(setup.obstacles), worlds.params[0],
                      worlds.state[0], worlds.rings[0], ring, dirs, ranges)  # fmt: skip
                want = lidar_scan(np.array([x, y, th]), field, n_rays=90, max_range=4.0).ranges
                np.testing.assert_array_equal(ranges, want)


def _grazing_poses(setup: EpisodeSetup, rel: np.ndarray) -> Iterator[tuple[float, float, float]]:
    """Poses whose beam ``r`` (every ``r`` in turn) runs just inside a body's vertex farthest
    from its centre, nearly tangent to its bounding disc: beams at the edge of the body's
    angular extent, meeting its edges near their ends."""
    for ob in setup.obstacles:
        assert isinstance(ob.body, PolygonBody)
        centre = np.asarray(ob.state.position, dtype=float)
        c, s = math.cos(ob.state.heading), math.sin(ob.state.heading)
        pts = ob.body.vertices @ np.array([[c, s], [-s, c]]) + centre
        v = pts[int(np.argmax(np.hypot(*(pts - centre).T)))]
        out = (v - centre) / np.hypot(*(v - centre))
        for side in (1.0, -1.0):
            tangent = side * np.array([-out[1], out[0]])
            for far in (0.6, 1.7, 3.4):
                p = v + far * tangent - 1e-4 * out
                bearing = math.atan2(v[1] - p[1], v[0] - p[0])
                for r in range(rel.shape[0]):
                    yield float(p[0]), float(p[1]), bearing - float(rel[r])


@pytest.mark.parametrize("compiled", [False, True])
@pytest.mark.parametrize("n_rays", [7, 32])
def test_the_lidar_culls_keep_the_beams_grazing_a_body(compiled: bool, n_rays: int) -> None:
    """Beams grazing each body at the edge of its angular extent, at every beam index: the
    kernel's ranges and the observation kernel's (beams culled by the bodies' bounding discs,
    headings near 0, 630 and 6280 rad) equal :func:`lidar_scan`'s, which casts every beam on
    every body in range; a disc test that is not safe (a disc 1e-6 narrower) fails here."""
    setup = build_episode(load_scenario("random-ch2:5"), 3)
    field = ObstacleField.from_obstacles(setup.obstacles)
    worlds = PackedWorlds(1)
    worlds.load(0, setup)
    rel = np.linspace(-math.pi, math.pi, n_rays, endpoint=False)
    turns = beam_turns(rel)
    ranges, dirs = np.empty(n_rays), np.empty((2, n_rays))
    ring = np.empty((2, worlds.rings.shape[3]))
    batch, out, dist = np.empty((1, n_rays)), np.empty((1, 4 + n_rays), np.float32), np.empty(1)
    hits = 0
    with kernels(compiled):
        lidar = kernel("lidar")
        for x, y, th0 in _grazing_poses(setup, rel):
            for th in (th0, th0 + 200.0 * math.pi, th0 - 2000.0 * math.pi):
                lidar(x, y, th, turns, 4.0, len(setup.obstacles), worlds.params[0],
                      worlds.state[0], worlds.rings[0], ring, dirs, ranges)  # fmt: skip
                worlds.robot[0] = (x, y, th)  # observe's path
                worlds.observe(rel, 4.0, 10.0, batch, out, dist)
                want = lidar_scan(np.array([x, y, th]), field, n_rays=n_rays, max_range=4.0)
                np.testing.assert_array_equal(ranges, want.ranges)
                np.testing.assert_array_equal(batch[0], want.ranges)
                hits += int((want.ranges < 4.0).sum())
    assert hits > 0


def test_a_restored_image_is_the_episode_load_builds() -> None:
    """restore() with episode 2's generators gives the slot load(build_episode(scene, 2)) gives,
    and the same steps after."""
    scene = load_scenario("random-ch2:4")
    fast, built = PackedWorlds(2), PackedWorlds(2)
    fast.load(0, build_episode(scene, 1))
    assert fast.restore(1, fast.image(0), world_rng(2).spawn(len(scene.obstacles)))
    built.load(0, build_episode(scene, 1))
    built.load(1, build_episode(scene, 2))
    for _ in range(400):
        for w in (fast, built):
            w.command[:] = (0.3, 0.2)
            w.step()
        for name in ("wf", "wi", "oi", "read", "params", "state", "ubuf", "rings"):
            np.testing.assert_array_equal(getattr(fast, name), getattr(built, name), name)
    assert not np.array_equal(fast.state[0], fast.state[1])


@pytest.mark.parametrize("compiled", [False, True])
def test_reseeded_generators_are_the_spawned_children_of_the_world_stream(compiled: bool) -> None:
    """reseed_spawned([k, 1], gens) leaves gens as world_rng(k).spawn(n)'s generators: the
    same PCG64 states and the same draws, for seeds of one, two and three 32-bit words."""
    with kernels(compiled):
        for k in [0, 1, 7, 2**31 - 2, 2**32, 2**40 + 3, 2**63 - 1, 2**70 + 5]:
            for n in (1, 10):
                want = world_rng(k).spawn(n)
                got = [np.random.default_rng(99) for _ in range(n)]
                reseed_spawned([k, 1], got)
                for g, w in zip(got, want, strict=True):
                    assert g.bit_generator.state == w.bit_generator.state, k
                    np.testing.assert_array_equal(g.random(5), w.random(5))


@pytest.mark.parametrize("compiled", [False, True])
def test_restore_spawned_is_the_episode_load_builds(compiled: bool) -> None:
    """restore_spawned() with entropy [k, 1] (world_rng(k)'s) gives slot 1 what
    load(build_episode(scene, k)) gives, over 300 steps and a top-up that reads its generators,
    and its generators end in the built episode's generators' states."""
    scene = load_scenario("random-ch2:4")
    n = len(scene.obstacles)
    with kernels(compiled):
        for k in (2, 2**40 + 3):
            fast, built = PackedWorlds(2), PackedWorlds(2)
            fast.load(0, build_episode(scene, 1))
            gens = [np.random.default_rng(99) for _ in range(n)]
            assert fast.restore_spawned(1, fast.image(0), [k, 1], gens)
            built.load(0, build_episode(scene, 1))
            built.load(1, build_episode(scene, k))
            for step in range(300):
                for w in (fast, built):
                    w.command[:] = (0.3, 0.2)
                    w.step()
                    if step == 150:  # every row read to half: all are topped up
                        w.oi[:, 1] = np.maximum(w.oi[:, 1], w.ubuf.shape[2] // 2)
                        w.refill()
            for name in ("wf", "wi", "oi", "read", "params", "state", "ubuf", "rings"):
                np.testing.assert_array_equal(getattr(fast, name), getattr(built, name), name)
            assert fast.read[1].max() > 0
            for g, w in zip(fast.rngs[1], built.rngs[1], strict=True):
                assert (g is None) == (w is None)
                if g is not None:
                    assert g.bit_generator.state == w.bit_generator.state


@pytest.mark.parametrize("compiled", [False, True])
def test_restore_spawned_many_is_restore_spawned_of_each(compiled: bool) -> None:
    """restore_spawned_many() of two slots leaves the arrays and generators that
    restore_spawned() of each leaves (seeds of one and two 32-bit words)."""
    scene = load_scenario("random-ch2:4")
    n = len(scene.obstacles)
    with kernels(compiled):
        many, each = PackedWorlds(3), PackedWorlds(3)
        for w in (many, each):
            w.load(0, build_episode(scene, 1))
        img = many.image(0)
        seeds = [2, 2**40 + 3]
        gens = [[np.random.default_rng(9) for _ in range(n)] for _ in seeds]
        assert many.restore_spawned_many([1, 2], img, seeds, 1, gens)
        gens1 = [[np.random.default_rng(9) for _ in range(n)] for _ in seeds]
        for slot, k, g in zip([1, 2], seeds, gens1, strict=True):
            assert each.restore_spawned(slot, img, [k, 1], g)
        for name in ("wf", "wi", "oi", "read", "params", "state", "ubuf", "rings"):
            np.testing.assert_array_equal(getattr(many, name), getattr(each, name), name)
        assert not np.array_equal(many.ubuf[1], many.ubuf[2])
        for slot in (1, 2):
            many.sync_generators(slot)
            each.sync_generators(slot)
            for g, h in zip(many.rngs[slot], each.rngs[slot], strict=True):
                assert (g is None) == (h is None)
                if g is not None:
                    assert g.bit_generator.state == h.bit_generator.state


@pytest.mark.parametrize("packed", [True, False])
def test_the_readings_arrays_are_what_the_readings_hold(packed: bool) -> None:
    """Both obstacle stores give readings whose arrays (made from the store's own arrays) are
    exactly what reading every reading gives, read-only, through a few steps."""
    with kernels(packed and numba_available()):
        world = World2D(build_episode(load_scenario("random-ch2:2"), 2), run_rng(2),
                        exact=False, packed=packed)  # fmt: skip
        world.start([False])
        for _ in range(3):
            for x, y in ((0.0, 0.0), (5.0, 5.0), (9.0, 2.0)):
                got = world.bodies.readings(x, y, 6.0)
                assert isinstance(got, Readings) or got == ()
                if got:
                    ref = read_arrays(tuple(got))
                    for a, b in zip(got.arrays, ref, strict=True):
                        assert a.shape == b.shape and np.array_equal(a, b)
                        assert not a.flags.writeable
            world.apply(UnicycleCommand(0.5, 0.3))
            for _ in range(4):
                world.advance()
