"""Packed 2D worlds: K unicycle worlds among rigid moving polygons, stepped in one compiled call.

The world of thesis Ch. 2 (unicycle (2.1)-(2.4) among rigid bodies moving and rotating as in
§2.2) for the cases that need speed more than generality: batched learning
(:mod:`uvnav.envs.nav2d_vec`) and the world-step benchmark.  Each world's state lives in rows of
preallocated arrays (robot pose and command, obstacle poses, random-turn draws, body rings), and
:func:`step_worlds_py` advances every running world by one decision (``control_period / dt``
integration steps) in one loop, compiled by numba when it is enabled (:func:`numba_enabled`).

The numbers are those of :class:`uvnav.sim.episode.World2D` with exact clearance, bit for
bit (the test suite compares them):

* robot: :func:`uvnav.dynamics.unicycle.unicycle_advance`, the same operations;
* obstacles: :class:`~uvnav.obstacles.motion.RandomTurn` and
  :class:`~uvnav.obstacles.motion.ConstantVelocity` with the operations of
  :class:`~uvnav.obstacles.batch.ObstacleBatch`.  A random-turn obstacle's draws come from its own
  generator, pre-drawn in rows of blocks (:meth:`PackedWorlds.refill`): ``Generator.random(n)``
  gives the same numbers as ``n`` calls of ``random()`` (and ``random(out=...)`` as many), so
  the stream is the one the lazy draws read;
* clearance: the signed distance of :meth:`uvnav.obstacles.ObstacleField.query` (the loop of
  :func:`uvnav.geometry.polygons.rings_nearest_py` on the transformed rings; the depth inside a
  body by numpy's ``hypot``, libm's, as the field takes it) minus the robot's radius; arrival
  uses :func:`pyhypot`, CPython's ``math.hypot`` (which is not libm's ``hypot``);
* lidar (:func:`~uvnav.sim.packed_sense.observe_py`): :func:`uvnav.sensors.lidar_scan`'s beams
  and ray-edge test.

Only these motions and polygon bodies are packed; :func:`pack_check` says why a scene is not.

The kernels live in :mod:`uvnav.sim.packed_kernels` (layout, motion, clearance, step) and
:mod:`uvnav.sim.packed_sense` (readings, lidar, observation vectors); this module re-exports them
and holds :class:`PackedWorlds`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.dynamics.unicycle import UnicycleSpec, unicycle_advance
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.kernels3d import compile_family, numba_enabled
from uvnav.geometry.polygons import ring_nearest_py
from uvnav.geometry.small import pyhypot
from uvnav.obstacles.bodies import PolygonBody
from uvnav.obstacles.motion import ConstantVelocity, RandomTurn
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle, ObstacleState
from uvnav.sim.ledger import decision_ratio, step_count
from uvnav.sim.packed_kernels import (
    BLOCK,
    COLLISION,
    CONSTANT,
    EMPTY,
    I_ACTIVE,
    I_NOBS,
    I_NSTEPS,
    I_RATIO,
    I_STATUS,
    I_STEP,
    N_PARAMS,
    N_STATE,
    NI,
    NW,
    O_KIND,
    O_UPOS,
    P_ARENA,
    P_BOUND,
    P_LIMIT,
    P_MIDX,
    P_MIDY,
    P_OMEGA,
    P_PERIOD,
    P_SPEED_LO,
    P_SPEED_SPAN,
    P_SPIN,
    P_TURN_LO,
    P_TURN_SPAN,
    P_VX,
    P_VY,
    P_X0,
    P_X1,
    P_Y0,
    P_Y1,
    RANDOM_TURN,
    ROW_BLOCKS,
    RUNNING,
    S_COURSE,
    S_HEADING,
    S_NEXT,
    S_OMEGA,
    S_SPEED,
    S_THRESHOLD,
    S_TURN,
    S_VX,
    S_VY,
    S_X,
    S_Y,
    STATUS_NAMES,  # noqa: F401 - re-exported
    SUCCESS,
    TIMEOUT,
    W_CLEAR,
    W_DT,
    W_GX,
    W_GY,
    W_LOW,
    W_RADIUS,
    W_TH,
    W_TOL,
    W_U,
    W_UMAX,
    W_V,
    W_VMAX,
    W_X,
    W_Y,
    _clearance,
    _hashmix,
    _mix,
    _move_obstacles,
    _mulhi,
    _pcg_step,
    _transform_ring,
    clearance_one_py,
    restore_many_py,
    spawn_fill_py,
    spawn_words_py,
    step_worlds_py,
)
from uvnav.sim.packed_sense import (  # noqa: F401 - the reading columns, re-exported
    NR,
    R_CENTRE,
    R_DIST,
    R_NEAR,
    R_OMEGA,
    R_VEL,
    _features,
    _lidar,
    _lidar_in,
    advance_one_py,
    commands_py,
    observe_py,
    outcome_py,
    sense_one_py,
    vector_one_py,
    vector_step_py,
)
from uvnav.sim.setup import EpisodeSetup

#: the kernels by short name, and everything they call (callees first)
_PUBLIC = {
    "step": "step_worlds_py",
    "observe": "observe_py",
    "advance_one": "advance_one_py",
    "sense_one": "sense_one_py",
    "clearance_one": "clearance_one_py",
    "lidar": "_lidar",
    "vector_one": "vector_one_py",
    "outcome": "outcome_py",
    "commands": "commands_py",
    "vector_step": "vector_step_py",
    "spawn_words": "spawn_words_py",
    "spawn_fill": "spawn_fill_py",
    "restore_many": "restore_many_py",
}
_KERNELS: dict[str, Callable[..., Any]] = {}


def kernel(name: str) -> Callable[..., Any]:
    """A kernel by short name (:data:`_PUBLIC`: ``"step"`` is :func:`step_worlds_py`...),
    compiled by numba on first use when it is enabled (:func:`numba_enabled`), else the Python
    function."""
    if not numba_enabled():
        return globals()[_PUBLIC[name]]
    if not _KERNELS:
        _KERNELS.update(compile_family([
            wrap_scalar, unicycle_advance, pyhypot, ring_nearest_py,
            _transform_ring, _move_obstacles, _clearance,
            _lidar_in, _lidar, _features, vector_one_py,
            step_worlds_py,
            observe_py,
            sense_one_py, advance_one_py, clearance_one_py, outcome_py, commands_py,
            vector_step_py,
            _hashmix, _mix, spawn_words_py, _mulhi, _pcg_step, spawn_fill_py,
            restore_many_py,
        ]))  # fmt: skip
    return _KERNELS[_PUBLIC[name]]


def direct(fn: Callable[..., Any], *args: Any) -> tuple[Any, Callable[..., Any]]:
    """``fn(*args)`` (a kernel of :func:`kernel`), and the function that runs the same machine
    code for arguments of these types without numba's dispatch (which types every argument at
    every call: 0.2-0.3 µs for sixteen of them); ``fn`` itself when it is not compiled.
    The caller passes that function arguments of the same types only: the same arrays (dtype,
    dimensions, layout), floats where these are floats, ints where these are ints."""
    out = fn(*args)
    overloads = getattr(fn, "overloads", None)
    if overloads is None:
        return out, fn
    if len(overloads) == 1:  # the call ran the only one (numba's typing costs ~0.3 ms)
        return out, next(iter(overloads.values())).entry_point
    from numba import typeof

    found = overloads.get(tuple(typeof(a) for a in args))
    return out, fn if found is None else found.entry_point


#: PCG64's multiplier and modulus (numpy's ``pcg64``)
_PCG_MULT = (2549297995355413924 << 64) + 4865540595714422341
_M128 = (1 << 128) - 1


def entropy_words(entropy: list[int]) -> np.ndarray:
    """``SeedSequence``'s run entropy of ``entropy`` (non-negative ints) as 32-bit words (int64,
    low word first, padded with zeros to the pool size 4): :func:`spawn_words_py`'s input."""
    words: list[int] = []
    for v in entropy:
        v = int(v)
        words.append(v & 0xFFFFFFFF)
        v >>= 32
        while v:
            words.append(v & 0xFFFFFFFF)
            v >>= 32
    words += [0] * (4 - len(words))
    return np.array(words, dtype=np.int64)


def set_pcg_state(generator: np.random.Generator, state: int, inc: int) -> None:
    """Set a PCG64 ``generator``'s state and increment (128-bit ints)."""
    generator.bit_generator.state = {"bit_generator": "PCG64", "has_uint32": 0, "uinteger": 0,
                                     "state": {"state": state, "inc": inc}}  # fmt: skip


def reseed_spawned(entropy: list[int], generators: list[np.random.Generator]) -> None:
    """Set ``generators`` (PCG64) to the states of ``np.random.default_rng(entropy).spawn(n)``'s
    ``n`` = ``len(generators)`` generators (``entropy``: non-negative ints), bit for bit,
    without building the seed sequences: their words by :func:`spawn_words_py`, PCG64's seeding
    (``pcg64_set_seed``) on Python ints.  A batched env's reset gives each of a world's
    obstacles the generator ``build_episode`` would, at a tenth of the cost."""
    out = np.empty((len(generators), 8), dtype=np.int64)
    kernel("spawn_words")(entropy_words(entropy), out)
    for g, w in zip(generators, out.tolist(), strict=True):
        seed = (w[1] << 96) | (w[0] << 64) | (w[3] << 32) | w[2]
        inc = ((((w[5] << 96) | (w[4] << 64) | (w[7] << 32) | w[6]) << 1) | 1) & _M128
        set_pcg_state(g, ((inc + seed) * _PCG_MULT + inc) & _M128, inc)


def pack_check(setup: EpisodeSetup) -> str | None:
    """Why ``setup`` cannot be packed (one line), or None: a unicycle among polygon bodies with
    :class:`ConstantVelocity` or :class:`RandomTurn` motion, each obstacle drawing from its own
    generator (the numbers are pre-drawn per obstacle)."""
    if type(setup.spec) is not UnicycleSpec:
        return f"the robot is a {type(setup.spec).__name__}, packed worlds hold unicycles"
    if setup.spec.kinematics != "arc":
        return f"the robot's kinematics is {setup.spec.kinematics}, packed worlds integrate arcs"
    if not setup.spec.ideal:
        return "the robot has acceleration limits, packed worlds hold ideal unicycles"
    owner: dict[int, int] = {}
    for j, ob in enumerate(setup.obstacles):
        rng = getattr(ob.motion, "rng", None)
        if rng is not None and owner.setdefault(id(rng), j) != j:
            return (
                f"obstacles {owner[id(rng)]} and {j} draw from one generator, packed worlds "
                "pre-draw each obstacle's numbers"
            )
        if not isinstance(ob.body, PolygonBody):
            return f"obstacle {j} is a {type(ob.body).__name__}, packed worlds hold polygons"
        if type(ob.motion) not in (ConstantVelocity, RandomTurn):
            return (
                f"obstacle {j} moves by {type(ob.motion).__name__}, packed worlds hold "
                "constant-velocity and random-turn motion"
            )
    return None


def _random_turn_columns(mod: RandomTurn, state: ObstacleState, st: list[float],
                         prm: list[float]) -> None:  # fmt: skip
    """A random-turn model's state (``S_*``: course, draws, next change) and parameters
    (``P_*``: draw ranges, period, spin, turn limit, arena) into the column lists."""
    st[S_COURSE] = mod.course_at(state)
    st[S_SPEED], st[S_TURN] = mod._speed, mod._turn
    st[S_NEXT] = mod._next_change
    st[S_THRESHOLD] = mod._next_change - 1e-12
    for lo_row, span_row, bounds in (
        (P_SPEED_LO, P_SPEED_SPAN, mod.speed),
        (P_TURN_LO, P_TURN_SPAN, mod.turn_rate),
    ):
        lo = float(bounds[0])
        span = float(bounds[1]) - lo
        if not (math.isfinite(span) and span >= 0.0):
            raise ValueError(f"random-turn bounds {tuple(bounds)} are not (low, high)")
        prm[lo_row], prm[span_row] = lo, span
    prm[P_PERIOD] = float(mod.change_period)
    prm[P_SPIN] = float(mod.spin)
    prm[P_LIMIT] = max(abs(mod.turn_rate[0]), abs(mod.turn_rate[1]))
    if mod.arena is not None:
        x0, y0, x1, y1 = mod.arena
        prm[P_ARENA] = 1.0
        prm[P_X0], prm[P_Y0], prm[P_X1], prm[P_Y1] = x0, y0, x1, y1
        prm[P_MIDX], prm[P_MIDY] = 0.5 * (x0 + x1), 0.5 * (y0 + y1)


class PackedWorlds:
    """``k`` slots of packed worlds (module docstring); :meth:`load` an episode into a slot,
    :meth:`step` the running ones by one decision, :meth:`observe` them.

    The arrays are the state (:func:`step_worlds_py` gives their layout; :attr:`robot`,
    :attr:`command`, :attr:`status`... are views of them).  A slot's random-turn obstacles keep
    their generators, read ahead by up to a row of pre-drawn numbers (:data:`ROW_BLOCKS` x
    :data:`BLOCK`, more where a decision has over :data:`BLOCK` integration steps): the models
    are not written back (unlike :meth:`World2D.close
    <uvnav.sim.episode.World2D.close>`).  A slot restored by :meth:`restore_spawned` (compiled)
    has its generators' states set at its next top-up, or by :meth:`sync_generators`.
    """

    oi: np.ndarray
    #: (k, M) numbers of each obstacle's generator read before its row's last top-up (with
    #: ``oi[:, O_UPOS]``: the numbers its draws have consumed)
    read: np.ndarray
    params: FloatArray
    state: FloatArray
    ubuf: FloatArray
    rings: FloatArray

    def __init__(self, k: int) -> None:
        self.k = int(k)
        self.wf = np.zeros((k, NW))
        self.wi = np.zeros((k, NI), dtype=np.int64)
        self.wi[:, I_STATUS] = TIMEOUT
        self.wi[:, I_ACTIVE] = 1
        self.wf[:, W_CLEAR] = self.wf[:, W_LOW] = math.inf
        self.rngs: list[list[np.random.Generator | None]] = [[] for _ in range(k)]
        self.safe_calls = 0  # step() calls before a refill may be needed
        self._templates: dict[tuple[int, ...], tuple[FieldTemplate, list[Any]]] = {}
        #: slots restored by :meth:`restore_spawned` whose generators' states are not yet set:
        #: (n, 4) uint64 states and increments (high and low words) after the draws
        self._pending: dict[int, np.ndarray] = {}
        self._alloc(0, 2, ROW_BLOCKS * BLOCK)

    # views of the state, by meaning
    @property
    def robot(self) -> FloatArray:
        """(k, 3) poses ``(x, y, theta)`` [m, m, rad]."""
        return self.wf[:, W_X : W_TH + 1]

    @property
    def command(self) -> FloatArray:
        """(k, 2) held commands ``(v, u)`` [m/s, rad/s], used as given (saturate them first)."""
        return self.wf[:, W_V : W_U + 1]

    @property
    def limits(self) -> FloatArray:
        """(k, 2) ``(V_max [m/s], U_max [rad/s])``."""
        return self.wf[:, W_VMAX : W_UMAX + 1]

    @property
    def clearance(self) -> FloatArray:
        """(k,) exact clearance after the last step [m] (``inf`` without obstacles)."""
        return self.wf[:, W_CLEAR]

    @property
    def low(self) -> FloatArray:
        """(k,) lowest clearance over the last :meth:`step` [m] (``inf`` where none ran)."""
        return self.wf[:, W_LOW]

    @property
    def status(self) -> np.ndarray:
        """(k,) status codes (:data:`STATUS_NAMES`)."""
        return self.wi[:, I_STATUS]

    @property
    def time(self) -> FloatArray:
        """(k,) simulated time [s] (step index x dt, as the loop world counts it)."""
        return self.wi[:, I_STEP] * self.wf[:, W_DT]

    def _alloc(self, m: int, w: int, b: int) -> None:
        """(Re)allocate the obstacle arrays for ``m`` obstacles of ``w``-column rings and ``b``
        pre-drawn numbers, keeping what the slots hold (the unread numbers move to the end of
        the longer rows, the next top-up fills the rest)."""
        k = self.k
        oi = np.zeros((k, 2, m), dtype=np.int64)
        oi[:, O_KIND] = EMPTY
        read = np.zeros((k, m), dtype=np.int64)
        params = np.zeros((k, N_PARAMS, m))
        state = np.zeros((k, N_STATE, m))
        ubuf = np.zeros((k, m, b))
        rings = np.zeros((k, 2, m, w))
        if hasattr(self, "oi"):
            m0, w0, b0 = self.rings.shape[2], self.rings.shape[3], self.ubuf.shape[2]
            oi[:, :, :m0] = self.oi
            moved = np.where(self.oi[:, O_KIND] == RANDOM_TURN, b - b0, 0)
            oi[:, O_UPOS, :m0] += moved
            read[:, :m0] = self.read - moved  # read + next unread: the numbers consumed
            params[:, :, :m0] = self.params
            state[:, :, :m0] = self.state
            ubuf[:, :m0, b - b0 :] = self.ubuf
            rings[:, :, :m0, :w0] = self.rings
            rings[:, :, :m0, w0:] = self.rings[:, :, :, :1]  # more copies of the first vertex
        self.oi, self.params, self.state, self.ubuf, self.rings = oi, params, state, ubuf, rings
        self.read = read
        self._fitted: tuple[np.ndarray, ...] | None = None  # (see _put)

    def load(self, slot: int, setup: EpisodeSetup) -> None:
        """Put ``setup``'s episode in ``slot`` as :meth:`World2D.start
        <uvnav.sim.episode.World2D.start>` begins it (status and clearance at t = 0).

        Raises:
            ValueError: the episode cannot be packed (:func:`pack_check`).
        """
        why = pack_check(setup)
        if why is not None:
            raise ValueError(why)
        obstacles = setup.obstacles
        m = len(obstacles)
        tpl = self._template([o.body for o in obstacles])
        spec, dt = setup.spec, float(setup.dt)
        ratio = decision_ratio(float(setup.control_period), dt)
        b = max(self.ubuf.shape[2], 4 * ratio)  # half a row: a decision's draws, 2 a step
        self.load_obstacles(slot, obstacles, tpl, b)
        x, y, th = (float(c) for c in np.asarray(setup.start, dtype=float)[:3])
        gx, gy = (float(c) for c in np.asarray(setup.goal, dtype=float)[:2])
        wf, wi = self.wf[slot], self.wi[slot]
        wf[:] = 0.0
        wf[[W_X, W_Y, W_TH, W_GX, W_GY]] = (x, y, th, gx, gy)
        wf[[W_RADIUS, W_TOL, W_DT]] = (float(spec.radius), float(setup.goal_tolerance), dt)
        wf[[W_VMAX, W_UMAX]] = (float(spec.v_max), float(spec.u_max))
        n_steps = step_count(float(setup.t_max), dt)
        wi[[I_STEP, I_RATIO, I_NSTEPS, I_NOBS]] = (0, ratio, n_steps, m)
        # at t = 0 as World2D.start measures it (the field's query), from the slot
        gap = float(kernel("clearance_one")(x, y, float(spec.radius), m, self.params[slot],
                                            self.state[slot], self.rings[slot])[0])  # fmt: skip
        wf[W_CLEAR], wf[W_LOW] = gap, math.inf
        status = RUNNING
        if gap < 0:
            status = COLLISION
        elif math.hypot(gx - x, gy - y) <= setup.goal_tolerance:
            status = SUCCESS
        wi[I_STATUS] = status
        # the slot's rows are full: a top-up is due no sooner for it than for the others
        self.safe_calls = min(self.safe_calls, b // (2 * ratio))

    def image(self, slot: int) -> tuple[np.ndarray, ...]:
        """Copies of ``slot``'s rows as :meth:`load` left them, for :meth:`restore`."""
        return tuple(a[slot].copy() for a in (self.wf, self.wi, self.oi, self.params, self.state,
                                               self.rings))  # fmt: skip

    def _fits(self, image: tuple[np.ndarray, ...]) -> bool:
        """The arrays' rows have :meth:`image`'s shapes (the last image that fitted is
        remembered until the arrays are reshaped)."""
        if image is not self._fitted:
            if any(a.shape[1:] != b.shape for a, b in zip(
                (self.wf, self.wi, self.oi, self.params, self.state, self.rings), image,
                strict=True,
            )):  # fmt: skip
                return False
            self._fitted = image
        return True

    def restore_spawned_many(self, slots: list[int], image: tuple[np.ndarray, ...],
                             seeds: list[int], key: int,
                             generators: list[list[np.random.Generator]]) -> bool:  # fmt: skip
        """:meth:`restore_spawned` of ``image`` into each of ``slots`` with entropy ``[seeds[i],
        key]`` and ``generators[i]``, the compiled part in one call; False (and nothing done)
        when the arrays have been reshaped since the image was taken."""
        if not numba_enabled() or not (0 <= key < 2**32 and all(0 <= k < 2**63 for k in seeds)):
            return all(self.restore_spawned(s, image, [k, key], g)
                       for s, k, g in zip(slots, seeds, generators, strict=True))  # fmt: skip
        if not self._fits(image):
            return False
        n = int(image[1][I_NOBS])
        pcg = np.empty((len(slots), len(generators[0]), 4), dtype=np.uint64)
        kernel("restore_many")(np.array(slots, dtype=np.int64), np.array(seeds, dtype=np.int64),
                               key, *image, self.wf, self.wi, self.oi, self.params, self.state,
                               self.rings, self.read, self.ubuf, pcg)  # fmt: skip
        drawn = [kind == RANDOM_TURN for kind in image[2][O_KIND, :n].tolist()]
        for s, gens, p in zip(slots, generators, pcg, strict=True):
            self.rngs[s] = [g if d else None for g, d in zip(gens, drawn, strict=False)]
            self._pending[s] = p
        ratio = int(image[1][I_RATIO])
        self.safe_calls = min(self.safe_calls, self.ubuf.shape[2] // (2 * ratio))
        return True

    def _put(self, slot: int, image: tuple[np.ndarray, ...]) -> bool:
        """Copy :meth:`image`'s rows into ``slot`` (no draws read yet); False (nothing done)
        when the arrays' rows no longer have its shapes.  The last image that fitted is
        remembered until the arrays are reshaped, sparing the shape checks."""
        if not self._fits(image):
            return False
        self.wf[slot], self.wi[slot], self.oi[slot] = image[0], image[1], image[2]
        self.params[slot], self.state[slot], self.rings[slot] = image[3], image[4], image[5]
        self.read[slot] = 0
        return True

    def restore(self, slot: int, image: tuple[np.ndarray, ...],
                generators: list[np.random.Generator]) -> bool:  # fmt: skip
        """Put :meth:`image`'s episode in ``slot`` with obstacle ``o``'s draws from
        ``generators[o]``: what :meth:`load` does for an episode of the same scene that differs
        only in its generators (the draws of :class:`RandomTurn` are the only numbers a scene
        seed changes), without building it.  False (and nothing done) when the arrays have been
        reshaped since the image was taken; :meth:`load` it then."""
        if not self._put(slot, image):
            return False
        self._pending.pop(slot, None)
        kinds = image[2][O_KIND]
        rngs: list[np.random.Generator | None] = []
        for o in range(int(image[1][I_NOBS])):
            rng = generators[o] if kinds[o] == RANDOM_TURN else None
            if rng is not None:
                rng.random(out=self.ubuf[slot, o])
            rngs.append(rng)
        self.rngs[slot] = rngs
        ratio = int(image[1][I_RATIO])
        self.safe_calls = min(self.safe_calls, self.ubuf.shape[2] // (2 * ratio))
        return True

    def restore_spawned(self, slot: int, image: tuple[np.ndarray, ...], entropy: list[int],
                        generators: list[np.random.Generator]) -> bool:  # fmt: skip
        """:meth:`restore` with ``generators`` (PCG64, one per obstacle) reseeded as
        :func:`reseed_spawned` (``entropy``, ``generators``) reseeds them: the same draws, seeded
        and drawn in one compiled call (:func:`spawn_fill_py`) when numba is enabled, the
        generators' own states then set only when a top-up next reads them
        (:meth:`sync_generators`)."""
        if not numba_enabled():
            reseed_spawned(entropy, generators)
            return self.restore(slot, image, generators)
        if not self._put(slot, image):
            return False
        kinds = image[2][O_KIND]
        pcg = np.empty((len(generators), 4), dtype=np.uint64)
        kernel("spawn_fill")(entropy_words(entropy), kinds, self.ubuf[slot], pcg)
        n = int(image[1][I_NOBS])
        self.rngs[slot] = [g if kinds[o] == RANDOM_TURN else None
                           for o, g in enumerate(generators[:n])]  # fmt: skip
        self._pending[slot] = pcg
        ratio = int(image[1][I_RATIO])
        self.safe_calls = min(self.safe_calls, self.ubuf.shape[2] // (2 * ratio))
        return True

    def sync_generators(self, slot: int) -> None:
        """Set the states of ``slot``'s generators to what its draws have consumed, where
        :meth:`restore_spawned` drew for them without setting them (nothing otherwise)."""
        pcg = self._pending.pop(slot, None)
        if pcg is None:
            return
        for g, (hi, lo, ihi, ilo) in zip(self.rngs[slot], pcg.tolist(), strict=False):
            if g is not None:
                set_pcg_state(g, (hi << 64) | lo, (ihi << 64) | ilo)

    def load_obstacles(self, slot: int, obstacles: list[Obstacle], tpl: FieldTemplate,
                       b: int) -> None:  # fmt: skip
        """Put ``obstacles`` (packable: :func:`pack_check`; ``tpl`` their bodies' template) in
        ``slot``, growing the arrays to hold them and ``b`` pre-drawn numbers a row."""
        m = len(obstacles)
        w = tpl.rings.shape[2] if m else 2
        if m > self.rings.shape[2] or w > self.rings.shape[3] or b > self.ubuf.shape[2]:
            self._alloc(max(m, self.rings.shape[2]), max(w, self.rings.shape[3]), b)
        self.wi[slot, I_NOBS] = m
        self._pending.pop(slot, None)
        self.oi[slot, O_KIND] = EMPTY
        self.oi[slot, O_UPOS] = 0
        self.read[slot] = 0
        self.rings[slot] = 0.0
        if m:
            self.rings[slot, :, :m, :w] = tpl.rings
            self.rings[slot, :, :m, w:] = tpl.rings[:, :, :1]
        self.rngs[slot] = [self._pack_obstacle(slot, o, ob) for o, ob in enumerate(obstacles)]
        self.params[slot, P_BOUND, :m] = tpl.bounding_radii

    def _template(self, bodies: list[Any]) -> FieldTemplate:
        """The bodies' packed geometry, kept for the episodes that share the body objects (the
        scenario's, see :meth:`BodySpec.to_body <uvnav.scenarios.schema.BodySpec.to_body>`)."""
        key = tuple(map(id, bodies))
        hit = self._templates.get(key)
        if hit is None:
            if len(self._templates) >= 64:
                self._templates.clear()
            hit = self._templates[key] = (FieldTemplate.from_bodies(bodies), bodies)
        return hit[0]

    def _pack_obstacle(self, slot: int, o: int, ob: Obstacle) -> np.random.Generator | None:
        """Obstacle ``o`` of ``slot``: its state, parameters and first block of draws; its
        generator (None for constant motion).  The columns are filled as lists and stored in one
        assignment each (a reset of the batched env packs every obstacle of its scene)."""
        mod, state = ob.motion, ob.state
        st, prm = [0.0] * N_STATE, [0.0] * N_PARAMS
        st[S_X], st[S_Y] = np.asarray(state.position, dtype=float).tolist()
        st[S_HEADING] = state.heading
        st[S_VX], st[S_VY] = np.asarray(state.velocity, dtype=float).tolist()
        st[S_OMEGA] = state.angular_velocity
        rng: np.random.Generator | None = None
        if isinstance(mod, ConstantVelocity):
            kind = CONSTANT
            prm[P_VX], prm[P_VY] = np.asarray(mod.velocity, dtype=float).tolist()
            prm[P_OMEGA] = float(mod.angular_velocity)
        else:
            assert isinstance(mod, RandomTurn)
            kind, rng = RANDOM_TURN, mod.rng
            _random_turn_columns(mod, state, st, prm)
        self.oi[slot, :, o] = (kind, 0)
        self.state[slot, :, o], self.params[slot, :, o] = st, prm
        if rng is not None:
            rng.random(out=self.ubuf[slot, o])
        return rng

    def refill(self) -> None:
        """Top up the draws of every obstacle that has read half its row or more: the unread
        ones move to the front, the rest are drawn.  Sets how many :meth:`step` calls are safe
        before the next top-up (a decision reads at most two numbers per integration step, and
        half a row holds a decision's worth: :meth:`load` sizes the rows).

        :meth:`step` calls it only when a row could run out in the next call (the step kernel
        counts the safe calls), and then every half-read row is topped up, so top-ups are rare
        and draw many numbers each: topping up one-block rows whenever one could run out cost
        1.2 (10 obstacles) and 1.8 µs (100) of a world step in
        ``benchmarks/peers/irsim_steps.py``, about 0.1 and 0.2 µs now (mostly the
        generators' calls).
        """
        b = self.ubuf.shape[2]
        upos = self.oi[:, O_UPOS]
        due = (upos >= b // 2).nonzero()
        for slot, o, p in zip(due[0].tolist(), due[1].tolist(), upos[due].tolist(), strict=True):
            if self._pending:
                self.sync_generators(slot)
            rng = self.rngs[slot][o]
            if rng is not None:
                row = self.ubuf[slot, o]
                row[: b - p] = row[p:]
                rng.random(out=row[b - p :])
        self.read[due] += upos[due]
        upos[due] = 0  # (a row without a generator is never read)
        spare = (b - upos) // np.maximum(2 * self.wi[:, I_RATIO, None], 1)
        self.safe_calls = int(spare.min()) if spare.size else 1 << 30

    def ensure_draws(self) -> None:
        """Top up the rows (:meth:`refill`) when the next call could run one out, and count that
        call: :meth:`step`'s rule, for a caller that steps the slots' arrays itself (one
        integration step a call, as :class:`~uvnav.sim.bodies2d.PackedBodies` does)."""
        if self.safe_calls <= 0:
            self.refill()
        self.safe_calls -= 1

    def step(self, active: np.ndarray | None = None) -> None:
        """Advance every running world (of the ``active`` (k,) bool slots) by one decision with
        the commands in :attr:`command`."""
        if active is not None:
            self.wi[:, I_ACTIVE] = active
        self.ensure_draws()  # its count is replaced by the kernel's, which knows the rows read
        self.safe_calls = kernel("step")(
            self.wf, self.wi, self.oi, self.params, self.state, self.ubuf, self.rings
        )
        if active is not None:
            self.wi[:, I_ACTIVE] = 1

    def observe(self, rel: FloatArray, max_range: float, goal_scale: float, ranges: FloatArray,
                out: np.ndarray, dist: FloatArray) -> None:  # fmt: skip
        """:func:`observe_py` on every slot (lidar beams at heading + ``rel`` [rad])."""
        kernel("observe")(self.wf, self.wi, self.params, self.state, self.rings, rel,
                          float(max_range), float(goal_scale), ranges, out, dist)  # fmt: skip
