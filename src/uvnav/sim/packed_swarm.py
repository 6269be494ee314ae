"""Packed swarms: N unicycles deciding by ``orca-shared-v1``, stepped in two compiled calls a step.

The multi-robot world of :mod:`uvnav.sim.multi` (thesis Ch. 8's robots that avoid each other;
unicycles (2.1)-(2.4) with disc bodies) for the case that needs speed more than generality: every
robot on ``orca-shared-v1`` with the same parameters (ORCA, van den Berg et al., ISRR 2009:
:mod:`uvnav.controllers.orca_shared`), exact sensing with known velocities, no obstacle besides
the robots.  A step is :func:`swarm_decide_py` (the group decision,
:func:`uvnav.controllers.orca_kernels.group_decide_py`, the kernel ``orca-shared-v1`` decides a
group with in the loop too, when one is due, and the commands held) then
:func:`swarm_advance_py` (the unicycles, robot-pair checks, arrivals, time limit: the step the
loop world :class:`~uvnav.sim.multi.MultiUnicycleWorld` takes for a world of robots only, through
:class:`SwarmState`): loops over preallocated arrays, compiled by numba when it is enabled; the
Python functions are the reference and the fallback.  Two calls, not one, so that the decisions
are timed as the one loop times a group's (:func:`uvnav.core.run_loop`: CPU and wall time divided
among the members).

It is :func:`uvnav.core.run_loop` over :class:`~uvnav.sim.multi.MultiUnicycleWorld` bit for bit
(the tests compare every pose, status, clearance and collided pair at every step, and the whole
:class:`~uvnav.sim.setup.MultiResult`), so :func:`~uvnav.sim.run.run_episode` runs such scenes
here (:func:`run_swarm`; campaigns and ``uvnav simulate`` with them):

* decisions: the group law's own kernel; each robot's decision clock is its law's
  (``FIRST_PERIOD`` at the first decision, then the time since the last, at least 1 ms); the
  perturbation's draws come from each law's generator (child 2i of the episode generator, as
  :meth:`MultiUnicycleWorld.law_setup` gives it), pre-drawn in blocks
  (``Generator.random(n)`` gives the numbers of ``n`` single draws);
* commands: :meth:`MultiUnicycleWorld.apply` (violations counted, effort of the speed change,
  :meth:`~uvnav.dynamics.unicycle.UnicycleCommand.clipped`); modes counted as
  :class:`uvnav.core.AgentLog` counts them;
* motion: :func:`~uvnav.dynamics.unicycle.unicycle_advance`; the path with
  :func:`~uvnav.geometry.small.pyhypot` (CPython's ``math.hypot``); the deadlock window's
  positions in a ring;
* pairs: the arithmetic of :class:`uvnav.sim.multi._DiscPairs` with numpy's ``hypot`` (libm's,
  not CPython's) where it uses it.

Decision times are measured, so they differ from run to run, as the loop's do.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from uvnav.controllers.base import LawState
from uvnav.controllers.orca_kernels import FAMILY, group_decide_py, hypot_versus_py
from uvnav.controllers.orca_shared import (
    BLOCK as BLOCK,
)
from uvnav.controllers.orca_shared import (
    Draws,
    OrcaShared,
    group_geometry,
)
from uvnav.core import AgentLog
from uvnav.dynamics.unicycle import unicycle_advance
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled
from uvnav.geometry.small import pyhypot
from uvnav.geometry.sweep import segment_gap
from uvnav.obstacles.bodies import DiscBody
from uvnav.obstacles.obstacle import _CULL_ABS, _CULL_REL, _X_AXIS, FieldTemplate
from uvnav.sim.ledger import Ledger, decision_ratio, group_outcome, step_count
from uvnav.sim.setup import MultiResult, MultiSetup

#: status codes of a packed robot (those of :mod:`uvnav.sim.packed`)
RUNNING, SUCCESS, COLLISION, TIMEOUT = 0, 1, 2, 3
_HIT = 4  # running when the pair check began, collided in it
STATUS_NAMES = ("running", "success", "collision", "timeout")
# Columns of the (N, NR) float array of the robots: pose [m, m, rad], held command [m/s, rad/s],
# velocity [m/s, m/s]; then a group's agent table (orca_kernels' G_* columns, from R_ORAD on):
# ORCA radius [m], ORCA neighbour range [m], goal [m], V_max [m/s], U_max [rad/s], time of the
# last decision [s] (NaN: none yet); then body radius [m], collision reach [m], disc radius and
# bounding radius of the body in the field [m], time reached [s] (NaN: not yet), path [m],
# clearance now and lowest [m], control effort, commands outside the limits, decisions taken,
# mode switches, last mode (-1: none yet, 0: M1, 1: M2), turn rate over the last step [rad/s] (0
# for a robot that did not move).
(R_X, R_Y, R_TH, R_V, R_U, R_VX, R_VY, R_ORAD, R_OREACH, R_GX, R_GY, R_VMAX, R_UMAX, R_LAST_T,
 R_RADIUS, R_REACH, R_DISC, R_BOUND, R_REACHED, R_PATH, R_CLEAR, R_LOW, R_EFFORT, R_VIOL, R_NDEC,
 R_SWITCH, R_MODE, R_W) = range(28)  # fmt: skip
NR = 28
# Entries of the int array of the swarm: step index, steps per decision, steps in the episode,
# 1 when the episode is over, max_neighbors, next slot and length of the position history.
(I_STEP, I_RATIO, I_NSTEPS, I_DONE, I_MAXNB, I_HNEXT, I_HLEN) = range(7)
# Entries of the float array of the swarm: dt [s], goal tolerance [m], perturbation [m/s], time
# horizon [s], responsibility, first decision period [s] (from F_EPS on: orca_kernels' P_*).
(F_DT, F_TOL, F_EPS, F_TAU, F_RESP, F_FIRST) = range(6)


#: length of the int and float arrays of the swarm (``I_*`` and ``F_*`` entries)
NI, NF = 7, 6


def int_views(
    iw: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The views of a packed swarm's int buffer ``iw`` (NI + 3 n + cap,) for n robots: its
    ``I_*`` entries, the status codes, each robot's next unread draw, the decision's members and
    its neighbour scratch (cap = max(max_neighbors, 1) entries)."""
    return (
        iw[:NI], iw[NI : NI + n], iw[NI + n : NI + 2 * n], iw[NI + 2 * n : NI + 3 * n],
        iw[NI + 3 * n :],
    )  # fmt: skip


def float_views(
    fw: FloatArray, n: int
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """The views of a packed swarm's float buffer ``fw`` (NF + 10 n + 8 cap,) for n robots: its
    ``F_*`` entries, the members' decision periods (n,), their draws (n, 2), the decision's
    output (n, 7) and the ORCA scratch (2 cap, 4)."""
    a, b, c = NF + n, NF + 3 * n, NF + 10 * n
    rows = (fw.shape[0] - c) // 4
    return (
        fw[:NF],
        fw[NF:a],
        fw[a:b].reshape((n, 2)),
        fw[b:c].reshape((n, 7)),
        fw[c:].reshape((rows, 4)),
    )


def swarm_check(setup: MultiSetup) -> str | None:
    """Why ``setup`` cannot be packed (one line), or None: no obstacle besides the robots, every
    robot on ``orca-shared-v1`` with the same parameters and exact sensing (velocities known)."""
    if setup.obstacles:
        return f"the world holds {len(setup.obstacles)} obstacle(s) besides the robots"
    keys = set()
    for i, r in enumerate(setup.robots):
        if not isinstance(r.controller, OrcaShared):
            return f"robot {i} is driven by {r.controller.name}, packed swarms hold orca-shared-v1"
        if r.sensing.velocities != "known":
            return f"robot {i} estimates velocities, packed swarms sense exactly"
        if r.spec.kinematics != "arc" or not r.spec.ideal:
            return f"robot {i} is not an ideal arc unicycle, packed swarms hold those"
        keys.add(r.controller.group_key)
    if len(keys) > 1:
        return "the robots' orca-shared-v1 parameters differ (more than one group)"
    return None


def _side_gaps(
    r: float, px: float, py: float, cx: float, cy: float, rad: float, own: float, chord: float,
    swept: bool,
) -> tuple[float, float]:  # fmt: skip
    """A robot at ``(px, py)`` of radius ``own``: its gap to the disc of radius ``rad`` at
    ``(cx, cy)``, ``r`` away (the disc kernel's arithmetic: the depth of a centre inside a disc,
    else ``max(r - rad, 0)``), and its least gap along the step (``chord``: the least centre
    distance over the step; the gap now when not ``swept``) [m]."""
    if r < rad:
        offx, offy = px - cx, py - cy
        if r > 0:
            ux, uy = offx / r, offy / r
        else:
            ux, uy = _X_AXIS[0], _X_AXIS[1]
        signed = -np.hypot(cx + ux * rad - px, cy + uy * rad - py)
    else:
        signed = max(r - rad, 0.0)
    gap = signed - own
    return gap, chord - (rad + own) if swept else gap


def _pair_check(
    rob: FloatArray, status: np.ndarray, pairs: np.ndarray, start: FloatArray, swept: bool
) -> None:
    """Clearances and collisions of the active robots (:meth:`MultiUnicycleWorld._check` with
    :class:`~uvnav.sim.multi._DiscPairs`' arithmetic) and, with ``swept``, of the pairs along the
    step from the positions ``start`` (N, 2), as :meth:`MultiUnicycleWorld._sweep_robots` judges
    them (:func:`~uvnav.geometry.sweep.segment_gap` on the robots' chords); a robot that collided
    stops.

    Each pair i < j is visited once: its centre distance and chord distance serve both robots
    (``hypot`` ignores signs and the chord's operations are those of the offsets negated, so
    either robot gets the numbers it would compute alone), and each robot's minima take its
    pairs in robot order, as a robot-by-robot pass does."""
    n = rob.shape[0]
    for i in range(n):
        rob[i, R_CLEAR] = math.inf
    for i in range(n):
        run_i = status[i] == RUNNING or status[i] == _HIT
        px, py = rob[i, R_X], rob[i, R_Y]
        lim_i = rob[i, R_REACH] * (1.0 + _CULL_REL) + _CULL_ABS * (1.0 + abs(px) + abs(py))
        for j in range(i + 1, n):
            run_j = status[j] == RUNNING or status[j] == _HIT
            if not (run_i or run_j):
                continue
            cx, cy = rob[j, R_X], rob[j, R_Y]
            r = np.hypot(cx - px, cy - py)  # = hypot(px - cx, py - cy): hypot ignores signs
            keep_i = run_i and (math.isinf(lim_i) or r - rob[j, R_BOUND] <= lim_i)
            keep_j = False
            if run_j:
                lim_j = rob[j, R_REACH] * (1.0 + _CULL_REL) + _CULL_ABS * (1.0 + abs(cx) + abs(cy))
                keep_j = math.isinf(lim_j) or r - rob[i, R_BOUND] <= lim_j
            if not (keep_i or keep_j):
                continue
            chord = 0.0
            if swept:
                chord = segment_gap(
                    start[i, 0] - start[j, 0], start[i, 1] - start[j, 1], px - cx, py - cy, 0.0
                )
            for k in range(2):  # robot i's side, then robot j's
                if not (keep_i if k == 0 else keep_j):
                    continue
                a, b = (i, j) if k == 0 else (j, i)
                gap, along = _side_gaps(
                    r, rob[a, R_X], rob[a, R_Y], rob[b, R_X], rob[b, R_Y], rob[b, R_DISC],
                    rob[a, R_RADIUS], chord, swept,
                )  # fmt: skip
                if gap < rob[a, R_CLEAR]:
                    rob[a, R_CLEAR] = gap
                if min(gap, along) < rob[a, R_LOW]:
                    rob[a, R_LOW] = min(gap, along)
                if gap < 0 or along < 0:
                    pairs[i, j] = 1
                    status[a] = _HIT
    for i in range(n):
        if status[i] == _HIT:
            status[i] = COLLISION


def _arrivals(rob: FloatArray, status: np.ndarray, t: float, tol: float) -> None:
    """Robots within ``tol`` of their goals arrive at ``t``."""
    for i in range(rob.shape[0]):
        if status[i] != RUNNING:
            continue
        if hypot_versus_py(rob[i, R_GX] - rob[i, R_X], rob[i, R_GY] - rob[i, R_Y], tol) <= tol:
            status[i], rob[i, R_REACHED] = SUCCESS, t


def hold_py(
    rob: FloatArray, members: np.ndarray, m: int, cmds: FloatArray, stepped: bool, period: float
) -> None:
    """Hold the commands ``cmds[k] = (V, u)`` of the robots ``members[k]`` (k < ``m``) as
    :meth:`MultiUnicycleWorld.apply` holds one: counted in ``R_VIOL`` when outside the limits
    (2.4) (:meth:`~uvnav.dynamics.unicycle.UnicycleCommand.violates`), saturated
    (:meth:`~uvnav.dynamics.unicycle.UnicycleCommand.clipped`: NaN and infinite components 0),
    the speed change's effort ``(V - V_held)^2 / period`` added once the episode has
    ``stepped``, into ``R_V`` and ``R_U``."""
    for k in range(m):
        i = members[k]
        v, u = cmds[k, 0], cmds[k, 1]
        vmax, umax = rob[i, R_VMAX], rob[i, R_UMAX]
        if v < -1e-9 or v > vmax + 1e-9 or abs(u) > umax + 1e-9:
            rob[i, R_VIOL] += 1.0
        if math.isfinite(v):
            v = 0.0 if v < 0.0 else v
            v = vmax if vmax < v else v
        else:
            v = 0.0
        if math.isfinite(u):
            u = -umax if -umax > u else u
            u = umax if umax < u else u
        else:
            u = 0.0
        if stepped:
            rob[i, R_EFFORT] += ((v - rob[i, R_V]) ** 2) / period
        rob[i, R_V], rob[i, R_U] = v, u


def swarm_decide_py(rob: FloatArray, draws: FloatArray, iw: np.ndarray, fw: FloatArray) -> int:
    """The decisions of the running robots when one is due (every ``ratio`` steps), held as
    :meth:`MultiUnicycleWorld.apply` holds them (limit violations counted, effort of the speed
    change, saturated; the mode of each decision counted as :class:`uvnav.core.AgentLog` counts
    it); returns how many robots decided.  ``draws`` (N, 2 BLOCK) holds each robot's pre-drawn
    numbers; the swarm's other arrays are views into two buffers (one array argument each, so
    the compiled call unboxes four): ``iw`` its ints (:func:`int_views`), ``fw`` its floats
    (:func:`float_views`)."""
    n = rob.shape[0]
    ints, status, upos, members, idx = int_views(iw, n)
    flt, periods, pick, out, scratch = float_views(fw, n)
    dt = flt[F_DT]
    step = ints[I_STEP]
    if step % ints[I_RATIO] != 0:
        return 0
    m = 0
    for i in range(n):
        if status[i] == RUNNING:
            members[m] = i
            m += 1
    if m == 0:
        return 0
    group_decide_py(
        members[:m], step * dt, flt[F_EPS:], ints[I_MAXNB], rob[:, R_ORAD:], draws, upos,
        rob[:, R_X:R_Y + 1], rob[:, R_TH], rob[:, R_VX:R_VY + 1], scratch, idx, periods, pick, out,
    )  # fmt: skip
    hold_py(rob, members, m, out, step != 0, ints[I_RATIO] * dt)
    for k in range(m):
        i = members[k]
        mode = out[k, 6]
        if rob[i, R_NDEC] > 0.0 and mode != rob[i, R_MODE]:
            rob[i, R_SWITCH] += 1.0
        rob[i, R_MODE] = mode
        rob[i, R_NDEC] += 1.0
    return m


def swarm_advance_py(
    rob: FloatArray,
    status: np.ndarray,
    pairs: np.ndarray,
    ints: np.ndarray,
    flt: FloatArray,
    hist: FloatArray,
) -> int:
    """One step ``dt`` (:meth:`MultiUnicycleWorld.advance`): the positions into the deadlock
    window's ring ``hist`` (W + 1, N, 2), the running robots moved, then pairs, clearances,
    collisions, arrivals and the time limit; returns 1 when the episode is over."""
    n = rob.shape[0]
    dt = flt[F_DT]
    slot = ints[I_HNEXT]
    for i in range(n):
        hist[slot, i, 0], hist[slot, i, 1] = rob[i, R_X], rob[i, R_Y]
    ints[I_HNEXT] = (slot + 1) % hist.shape[0]
    if ints[I_HLEN] < hist.shape[0]:
        ints[I_HLEN] += 1
    for i in range(n):
        if status[i] != RUNNING:
            rob[i, R_VX] = rob[i, R_VY] = rob[i, R_W] = 0.0
            continue
        x, y, u = rob[i, R_X], rob[i, R_Y], rob[i, R_U]
        rob[i, R_W] = u
        rob[i, R_EFFORT] += u * u * dt
        nx, ny, nth = unicycle_advance(x, y, rob[i, R_TH], rob[i, R_V], u, dt)
        rob[i, R_PATH] += pyhypot(nx - x, ny - y)
        rob[i, R_X], rob[i, R_Y], rob[i, R_TH] = nx, ny, nth
        rob[i, R_VX] = rob[i, R_V] * math.cos(nth)
        rob[i, R_VY] = rob[i, R_V] * math.sin(nth)
    step = ints[I_STEP] + 1
    ints[I_STEP] = step
    _pair_check(rob, status, pairs, hist[slot], True)
    _arrivals(rob, status, step * dt, flt[F_TOL])
    running = False
    for i in range(n):
        if status[i] == RUNNING:
            running = True
    done = 1 if (not running or step >= ints[I_NSTEPS]) else 0
    ints[I_DONE] = done
    return done


_KERNELS: dict[str, Callable[..., Any]] = {}
_cpu_clock, _wall_clock = _time.thread_time_ns, _time.perf_counter_ns  # the decision timers


def _kernel(name: str) -> Callable[..., Any]:
    """The function ``name`` of this module's kernels (:func:`swarm_decide_py`,
    :func:`swarm_advance_py`, :func:`_pair_check`, :func:`hold_py`), compiled when numba is
    enabled."""
    if not numba_enabled():
        plain: dict[str, Callable[..., Any]] = {
            "swarm_decide_py": swarm_decide_py,
            "swarm_advance_py": swarm_advance_py,
            "_pair_check": _pair_check,
            "hold_py": hold_py,
        }
        return plain[name]
    if not _KERNELS:
        _KERNELS.update(compile_family(
            (*FAMILY, unicycle_advance, segment_gap, _side_gaps, _pair_check, _arrivals, hold_py,
             int_views, float_views, swarm_decide_py, swarm_advance_py)
        ))  # fmt: skip
    return _KERNELS[name]


def hold_kernel() -> Callable[..., Any]:
    """:func:`hold_py`, compiled when numba is enabled."""
    return _kernel("hold_py")


def _kernels() -> tuple[Callable[..., Any], Callable[..., Any]]:
    """:func:`swarm_decide_py` and :func:`swarm_advance_py`, compiled when numba is enabled."""
    return _kernel("swarm_decide_py"), _kernel("swarm_advance_py")


def _robots(setup: MultiSetup) -> Sequence[Any]:
    """The scene's robots.

    Raises:
        ValueError: there is none.
    """
    if not setup.robots:
        raise ValueError("a multi-robot episode needs at least one robot")
    return setup.robots


class SwarmState:
    """N ideal arc unicycles with disc bodies and nothing else in the world, in packed arrays,
    each step one call of :func:`swarm_advance_py` (compiled when numba is enabled): the arrays
    the loop world :class:`~uvnav.sim.multi.MultiUnicycleWorld` steps such a world with, and
    :class:`PackedSwarm`'s.  The checks and arrivals at t = 0 are done here (as
    :meth:`MultiUnicycleWorld.start` does them).

    Args:
        setup: the scene (no obstacle besides the robots; every robot an ideal arc unicycle).

    Attributes:
        rob: (N, NR) the robots (``R_*`` columns; the ORCA columns left at 0).
        status: (N,) status codes (``RUNNING`` until arrival or collision).
        pairs: (N, N) 1 where robots i < j overlapped at some step.
        start_dist: (N,) each robot's distance to its goal at the start [m].

    Raises:
        ValueError: no robot, or ``control_period`` is not a whole multiple of ``dt``.
    """

    def __init__(self, setup: MultiSetup, extra_ints: int = 0, extra_floats: int = 0) -> None:
        robots = _robots(setup)
        n = len(robots)
        dt = float(setup.dt)
        self.setup, self.n, self.dt = setup, n, dt
        radii = np.array([float(r.spec.radius) for r in robots])
        template = FieldTemplate.from_bodies([DiscBody(max(r, 1e-6)) for r in radii])
        rob = np.zeros((n, NR))
        rob[:, R_X : R_TH + 1] = [np.asarray(r.start, dtype=float)[:3] for r in robots]
        th = rob[:, R_TH]
        rob[:, R_VX], rob[:, R_VY] = 0.0 * np.cos(th), 0.0 * np.sin(th)  # held speed 0
        rob[:, R_GX : R_GY + 1] = [np.asarray(r.goal, dtype=float)[:2] for r in robots]
        rob[:, R_RADIUS] = radii
        floor = 4.0 * float(radii.max()) + 1.0  # the reach covers any robot that can touch
        rob[:, R_REACH] = [max(float(r.sensing.sensing_range), floor) for r in robots]
        rob[:, R_VMAX] = [float(r.spec.v_max) for r in robots]
        rob[:, R_UMAX] = [float(r.spec.u_max) for r in robots]
        rob[:, R_DISC], rob[:, R_BOUND] = template.radii, template.bounding_radii
        rob[:, R_REACHED] = rob[:, R_LAST_T] = np.nan
        rob[:, R_CLEAR] = rob[:, R_LOW] = np.inf
        rob[:, R_MODE] = -1.0
        self.rob = rob
        self.iw = np.zeros(NI + n + extra_ints, dtype=np.int64)  # ints, status, then extra
        self.fw = np.zeros(NF + extra_floats)  # flt, then extra
        self.ints, self.status = self.iw[:NI], self.iw[NI : NI + n]
        self.pairs = np.zeros((n, n), dtype=np.uint8)
        self.ints[:] = (
            0, decision_ratio(float(setup.control_period), dt), step_count(setup.t_max, dt), 0,
            0, 0, 0,
        )  # fmt: skip
        self.flt = self.fw[:NF]
        self.flt[:] = (dt, float(setup.goal_tolerance), 0.0, 0.0, 0.0, LawState.FIRST_PERIOD)
        window = max(1, round(setup.deadlock_window / dt))
        self.hist = np.zeros((window + 1, n, 2))  # the last window + 1 positions before a step
        self.advance_kernel = _kernel("swarm_advance_py")  # its arguments: _advance_args
        self._advance_args = (self.rob, self.status, self.pairs, self.ints, self.flt, self.hist)
        _kernel("_pair_check")(rob, self.status, self.pairs, rob[:, R_X : R_Y + 1], False)
        self.start_dist = np.hypot(*(rob[:, R_GX : R_GY + 1] - rob[:, R_X : R_Y + 1]).T)
        for i in range(n):
            if self.status[i] == RUNNING and self.start_dist[i] <= self.flt[F_TOL]:
                self.status[i], rob[i, R_REACHED] = SUCCESS, 0.0
        over = not bool(np.any(self.status == RUNNING)) or self.ints[I_NSTEPS] <= 0
        self.ints[I_DONE] = int(over)

    def advance(self) -> bool:
        """One step ``dt`` (:func:`swarm_advance_py`); returns whether the episode is over."""
        return bool(self.advance_kernel(*self._advance_args))

    def reached(self) -> list[float | None]:
        """Each robot's arrival time [s] (``None`` before)."""
        return [None if r != r else float(r) for r in self.rob[:, R_REACHED].tolist()]

    def window_start(self) -> FloatArray | None:
        """The positions at the start of the deadlock window (``None`` before the first step)."""
        hlen, cap = int(self.ints[I_HLEN]), self.hist.shape[0]
        return self.hist[(int(self.ints[I_HNEXT]) - hlen) % cap] if hlen else None

    def collided_pairs(self) -> list[tuple[int, int]]:
        """The robot pairs (i < j) that overlapped."""
        return [(int(i), int(j)) for i, j in zip(*np.nonzero(self.pairs), strict=True)]

    def ledger(self, i: int, status: str) -> Ledger:
        """Robot i's :class:`~uvnav.sim.ledger.Ledger` with status ``status``."""
        rob, reached = self.rob, float(self.rob[i, R_REACHED])
        return Ledger.settled(
            float(self.flt[F_TOL]), status=status, start_dist=float(self.start_dist[i]),
            reached_at=None if reached != reached else reached, path=float(rob[i, R_PATH]),
            effort=float(rob[i, R_EFFORT]), violations=int(rob[i, R_VIOL]),
            min_clear=float(rob[i, R_LOW]),
        )  # fmt: skip

    def ledgers(self, status: Sequence[str]) -> list[Ledger]:
        """Each robot's :class:`~uvnav.sim.ledger.Ledger` with status ``status[i]``."""
        return [self.ledger(i, status[i]) for i in range(self.n)]


class PackedSwarm(SwarmState):
    """One multi-robot episode of ``orca-shared-v1`` robots in packed arrays (module docstring):
    a :class:`SwarmState` whose robots decide in :func:`swarm_decide_py`.

    Args:
        setup: the scene (:func:`swarm_check` must pass); its laws' parameters are read, the
            laws themselves are not called.
        rng: the episode generator, spawned as :class:`~uvnav.sim.multi.MultiUnicycleWorld`
            spawns it (robot i's law draws from child 2i).

    Attributes:
        status: (N,) status codes (``RUNNING`` until arrival or collision; ``TIMEOUT`` at the end).

    Raises:
        ValueError: the scene cannot be packed (the reason in one line), or ``control_period``
            is not a whole multiple of ``dt``.
    """

    def __init__(self, setup: MultiSetup, rng: np.random.Generator) -> None:
        reason = swarm_check(setup)
        if reason is not None:
            raise ValueError(f"cannot pack this swarm: {reason}")
        law: Any = _robots(setup)[0].controller
        p = law.params
        n, cap = len(setup.robots), max(int(p.max_neighbors), 1)
        super().__init__(setup, extra_ints=2 * n + cap, extra_floats=10 * n + 8 * cap)
        rob = self.rob
        radii = rob[:, R_RADIUS].copy()
        sensing = np.array([float(r.sensing.sensing_range) for r in setup.robots])
        rob[:, R_ORAD], rob[:, R_OREACH] = group_geometry(p, radii, sensing)
        self.ints[I_MAXNB] = int(p.max_neighbors)
        self.flt[F_EPS : F_RESP + 1] = (
            float(p.perturbation),
            float(p.time_horizon),
            float(p.responsibility),
        )
        upos = int_views(self.iw, n)[2]
        self._draws = Draws(rng.spawn(2 * n)[0::2], float(p.perturbation), upos)  # child 2i: law i
        self._ready = self._draws.ready
        self._decide = _kernel("swarm_decide_py")
        self._decide_args = (rob, self._draws.draws, self.iw, self.fw)
        self._cpu_ns: list[int] = []  # each group decision's CPU and wall time per member [ns]
        self._wall_ns: list[int] = []
        self._finish()

    def _finish(self) -> None:
        self._over = bool(self.ints[I_DONE])
        if self._over:
            self.status[self.status == RUNNING] = TIMEOUT

    @property
    def done(self) -> bool:
        """The episode is over (every robot arrived or collided, or the time limit)."""
        return bool(self.ints[I_DONE])

    @property
    def step_index(self) -> int:
        return int(self.ints[I_STEP])

    @property
    def t(self) -> float:
        """Time now [s]."""
        return self.step_index * self.dt

    def step(self) -> bool:
        """One iteration of the loop: the decisions when due (their CPU and wall time kept, as
        :func:`uvnav.core.run_loop` keeps a group's), then one step ``dt``; returns
        :attr:`done`."""
        if self._over:
            return True
        self._ready()
        c0, w0 = _cpu_clock(), _wall_clock()
        m = self._decide(*self._decide_args)
        if m:
            c1, w1 = _cpu_clock(), _wall_clock()
            self._cpu_ns.append((c1 - c0) // m)
            self._wall_ns.append((w1 - w0) // m)
        if self.advance_kernel(*self._advance_args):
            self._over = True
            self._finish()
        return self._over

    def run(self) -> None:
        """Step to the end."""
        while not self.step():
            pass

    def statuses(self) -> list[str]:
        """Each robot's status name (``running`` while the episode goes on)."""
        return [STATUS_NAMES[s] for s in self.status.tolist()]

    def logs(self) -> list[AgentLog]:
        """Each robot's :class:`~uvnav.core.AgentLog`: its mode switches, and its share of every
        group decision it took (a robot decides at every decision time from the start until it
        arrives or collides, so its decisions are the first ``R_NDEC`` of the group's)."""
        out = []
        for i in range(self.n):
            k = int(self.rob[i, R_NDEC])
            mode = int(self.rob[i, R_MODE])
            out.append(AgentLog(
                mode_switches=int(self.rob[i, R_SWITCH]),
                decision_us=[c / 1000.0 for c in self._cpu_ns[:k]],
                decision_wall_us=[w / 1000.0 for w in self._wall_ns[:k]],
                last_mode="" if mode < 0 else ("M2" if mode else "M1"),
                _decided=k > 0,
            ))  # fmt: skip
        return out

    def result(self, poses: Sequence[FloatArray] = (), times: Sequence[float] = ()) -> MultiResult:
        """The episode's :class:`~uvnav.sim.setup.MultiResult` (``poses`` / ``times``: the
        recorded poses before each step and at the end, as :class:`PosesProbe` records them)."""
        rob, setup = self.rob, self.setup
        status = self.statuses()
        pairs = self.collided_pairs()
        books, logs = self.ledgers(status), self.logs()
        robots = [
            book.metrics(log, top_speed=float(r.spec.v_max))
            for book, log, r in zip(books, logs, setup.robots, strict=True)
        ]
        return MultiResult(
            robots=robots,
            statuses=status,
            group=group_outcome(
                setup,
                status,
                self.reached(),
                rob[:, R_X : R_Y + 1],
                self.window_start(),
                self.t,
                len(pairs),
                0,
            ),
            times=np.asarray(times) if len(times) else np.zeros(0),
            poses=np.asarray(poses) if len(poses) else np.zeros((0, self.n, 3)),
            collided_pairs=pairs,
        )


def run_swarm(setup: MultiSetup, rng: np.random.Generator, *, record: bool = True) -> MultiResult:
    """:func:`uvnav.sim.run.run_episode`'s episode in a :class:`PackedSwarm` (the same result,
    decision times apart); ``record`` keeps every robot's pose at every step."""
    swarm = PackedSwarm(setup, rng)
    poses: list[FloatArray] = []
    times: list[float] = []
    while True:
        if record:
            times.append(swarm.t)
            poses.append(swarm.rob[:, R_X : R_TH + 1].copy())
        if swarm.done:
            break
        swarm.step()
    return swarm.result(poses, times)
