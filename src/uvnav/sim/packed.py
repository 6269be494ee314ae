"""Packed 2D worlds: K unicycle worlds among rigid moving polygons, stepped in one compiled call.

The world of thesis Ch. 2 (unicycle (2.1)-(2.4) among rigid bodies moving and rotating as in
§2.2) for the cases that need speed more than generality: batched learning
(:mod:`uvnav.envs.nav2d_vec`) and the world-step benchmark.  Each world's state lives in rows of
preallocated arrays (robot pose and command, obstacle poses, random-turn draws, body rings), and
:func:`step_worlds_py` advances every running world by one decision (``control_period / dt``
integration steps) in one loop, compiled by numba when it is enabled (:func:`numba_enabled`).

The numbers are those of :class:`uvnav.sim.episode.UnicycleWorld` with exact clearance, bit for
bit (the test suite compares them):

* robot: :func:`uvnav.dynamics.unicycle.unicycle_advance`, the same operations;
* obstacles: :class:`~uvnav.obstacles.motion.RandomTurn` and
  :class:`~uvnav.obstacles.motion.ConstantVelocity` with the operations of
  :class:`~uvnav.obstacles.batch.ObstacleBatch`.  A random-turn obstacle's draws come from its own
  generator, pre-drawn in blocks (:meth:`PackedWorlds.refill`): ``Generator.random(n)`` gives the
  same numbers as ``n`` calls of ``random()``, so the stream is the one the lazy draws read;
* clearance: the signed distance of :meth:`uvnav.obstacles.ObstacleField.query` (the loop of
  :func:`uvnav.geometry.polygons.rings_nearest_py` on the transformed rings) minus the robot's
  radius; arrival uses :func:`pyhypot`, CPython's ``math.hypot`` (which is not libm's ``hypot``);
* lidar (:func:`lidar_worlds_py`): :func:`uvnav.sensors.lidar_scan`'s beams and ray-edge test.

Only these motions and polygon bodies are packed; :func:`pack_check` says why a scene is not.
"""

from __future__ import annotations

import math
import types
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import numba_enabled
from uvnav.obstacles.bodies import PolygonBody
from uvnav.obstacles.motion import ConstantVelocity, RandomTurn
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle
from uvnav.sim.episode import EpisodeSetup, decision_ratio

#: status codes of a packed world
RUNNING, SUCCESS, COLLISION, TIMEOUT = 0, 1, 2, 3
STATUS_NAMES = ("running", "success", "collision", "timeout")
#: motion kinds of a packed obstacle (-1: an empty slot)
EMPTY, CONSTANT, RANDOM_TURN = -1, 0, 1
_EPS_UNI = float(np.finfo(float).eps)  # unicycle_advance's sinc guard
_EPS_RING = 1e-12  # the rings kernels' degenerate-edge guard
_DBL_MIN = 2.2250738585072014e-308
_VELTKAMP = 134217729.0  # 2**27 + 1
#: random numbers pre-drawn per obstacle and block
BLOCK = 64

# Parameter rows of the (K, P, M) obstacle parameter array.
(P_VX, P_VY, P_OMEGA, P_SPEED_LO, P_SPEED_SPAN, P_TURN_LO, P_TURN_SPAN, P_PERIOD, P_SPIN,
 P_X0, P_Y0, P_X1, P_Y1, P_MIDX, P_MIDY, P_LIMIT, P_ARENA, P_BOUND) = range(18)  # fmt: skip
N_PARAMS = 18
# State rows of the (K, S, M) obstacle state array.
S_X, S_Y, S_HEADING, S_COURSE, S_SPEED, S_TURN, S_NEXT, S_THRESHOLD = range(8)
N_STATE = 8


def pyhypot(x: float, y: float) -> float:
    """CPython's ``math.hypot(x, y)`` (its ``vector_norm``: scaled, error-free squares and sums,
    one differential correction), operation for operation, so compiled code gets its numbers.

    libm's ``hypot`` (numpy's, numba's) differs from it in the last bit for about 0.6 % of
    inputs; the simulator's arrival test and the env's distances use ``math.hypot``.

    >>> import math
    >>> pyhypot(3.0, 4.0), pyhypot(-0.0, 0.0), pyhypot(1e-310, 0.0) == math.hypot(1e-310, 0.0)
    (5.0, 0.0, True)
    >>> pyhypot(math.inf, math.nan), math.isnan(pyhypot(1.0, math.nan))
    (inf, True)
    """
    x = abs(x)
    y = abs(y)
    if math.isinf(x) or math.isinf(y):
        return math.inf
    if x != x or y != y:
        return math.nan
    big = x if x > y else y
    if big == 0.0:
        return big
    outer = 1.0
    _, e = math.frexp(big)
    if e < -1021:  # subnormal: scaled up first, as CPython does
        x /= _DBL_MIN
        y /= _DBL_MIN
        outer = _DBL_MIN
        _, e = math.frexp(x if x > y else y)
    scale = math.ldexp(1.0, -e)
    csum, frac1, frac2 = 1.0, 0.0, 0.0
    for v in (x * scale, y * scale):
        t = v * _VELTKAMP  # Dekker's exact square v * v = z + zz
        hi = t - (t - v)
        lo = v - hi
        p, q = hi * hi, hi * lo + lo * hi
        z = p + q
        zz = p - z + q + lo * lo
        s = csum + z  # exact sum csum + z = s + (csum - s) + z
        frac1 += zz
        frac2 += (csum - s) + z
        csum = s
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    t, t2 = -h * _VELTKAMP, h * _VELTKAMP  # exact product -h * h
    hi, hi2 = t - (t + h), t2 - (t2 - h)
    lo, lo2 = -h - hi, h - hi2
    p, q = hi * hi2, hi * lo2 + lo * hi2
    z = p + q
    zz = p - z + q + lo * lo2
    s = csum + z
    frac1 += zz
    frac2 += (csum - s) + z
    csum = s
    h += (csum - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return outer * (h / scale)


def wrap_angle(a: float) -> float:
    """:func:`uvnav.geometry.angles.wrap_scalar` (to (-pi, pi] [rad]) for compiled code."""
    if -math.pi < a <= math.pi:
        return a
    w = math.pi - (math.pi - a) % (2.0 * math.pi)
    return w if w > -math.pi else math.pi


def _obstacle_step(o: int, st: FloatArray, prm: FloatArray, kind: int, ubuf: FloatArray,
                   upos: np.ndarray, t: float, dt: float) -> None:  # fmt: skip
    """Advance obstacle ``o`` of one world (``st`` (S, M), ``prm`` (P, M)) from ``t`` by
    ``dt`` [s]: :class:`ObstacleBatch`'s arithmetic for its motion ``kind``."""
    if kind == CONSTANT:
        st[S_HEADING, o] = wrap_angle(st[S_HEADING, o] + prm[P_OMEGA, o] * dt)
        st[S_X, o] = st[S_X, o] + prm[P_VX, o] * dt
        st[S_Y, o] = st[S_Y, o] + prm[P_VY, o] * dt
        return
    if t >= st[S_THRESHOLD, o]:  # a new speed and turn rate (RandomTurn.step's two draws)
        p = upos[o]
        st[S_SPEED, o] = prm[P_SPEED_LO, o] + prm[P_SPEED_SPAN, o] * ubuf[o, p]
        st[S_TURN, o] = prm[P_TURN_LO, o] + prm[P_TURN_SPAN, o] * ubuf[o, p + 1]
        upos[o] = p + 2
        nc = t + prm[P_PERIOD, o]
        st[S_NEXT, o] = nc
        st[S_THRESHOLD, o] = nc - 1e-12
    turn = st[S_TURN, o]
    px, py = st[S_X, o], st[S_Y, o]
    if prm[P_ARENA, o] > 0.0 and not (
        prm[P_X0, o] <= px <= prm[P_X1, o] and prm[P_Y0, o] <= py <= prm[P_Y1, o]
    ):  # outside its arena: turn back toward the centre at the largest rate
        to_c = math.atan2(prm[P_MIDY, o] - py, prm[P_MIDX, o] - px)
        lim = prm[P_LIMIT, o]
        turn = min(max(wrap_angle(to_c - st[S_COURSE, o]) / dt, -lim), lim)
    om = turn + prm[P_SPIN, o]
    course = wrap_angle(st[S_COURSE, o] + turn * dt)
    st[S_HEADING, o] = wrap_angle(st[S_HEADING, o] + om * dt)
    st[S_COURSE, o] = course
    mid = course - 0.5 * turn * dt
    speed = st[S_SPEED, o]
    st[S_X, o] = px + math.cos(mid) * speed * dt
    st[S_Y, o] = py + math.sin(mid) * speed * dt


def _signed_distance(px: float, py: float, rings: FloatArray, o: int, c: float, s: float,
                     cx: float, cy: float) -> float:  # fmt: skip
    """Signed distance [m] from ``(px, py)`` to polygon ``o`` of ``rings`` (2, M, W) turned by
    (``c``, ``s``) = (cos, sin) of its heading and moved to ``(cx, cy)``: the nearest boundary
    distance outside, minus it inside (:meth:`ObstacleField.query`'s ``signed``)."""
    best, bx, by, seen_nan = math.inf, math.nan, math.nan, False
    crossings = 0
    rx, ry = rings[0, o, 0], rings[1, o, 0]
    sx, sy = c * rx + s * -ry + cx, c * ry + s * rx + cy
    for j in range(rings.shape[2] - 1):
        rx, ry = rings[0, o, j + 1], rings[1, o, j + 1]
        nx, ny = c * rx + s * -ry + cx, c * ry + s * rx + cy
        ex, ey = nx - sx, ny - sy
        ee = ex * ex + ey * ey
        if not ee >= _EPS_RING and ee == ee:
            ee = _EPS_RING
        u = ((px - sx) * ex + (py - sy) * ey) / ee
        if u < 0.0:
            u = 0.0
        if u > 1.0:
            u = 1.0
        qx, qy = sx + u * ex, sy + u * ey
        dx, dy = qx - px, qy - py
        d = math.sqrt(dx * dx + dy * dy)
        if not seen_nan and (d != d or d < best or j == 0):
            best, bx, by, seen_nan = d, qx, qy, d != d
        if (sy > py) != (ny > py) and sx + (py - sy) * ex / ey > px:
            crossings += 1
        sx, sy = nx, ny
    if crossings % 2 == 1:
        return -math.hypot(bx - px, by - py)
    return best


def _clearance(k: int, x: float, y: float, radius: float, n_obs: np.ndarray,
               params: FloatArray, state: FloatArray, rings: FloatArray) -> float:  # fmt: skip
    """World ``k``'s exact clearance [m] of the robot disc at ``(x, y)``; ``inf`` without
    obstacles."""
    gap = math.inf
    st = state[k]
    slack = 1e-9 * (1.0 + abs(x) + abs(y))
    for o in range(n_obs[k]):
        # a body whose bounding disc is farther than the gap so far cannot lower it
        lower = math.hypot(st[S_X, o] - x, st[S_Y, o] - y) - params[k, P_BOUND, o] - radius
        if lower > gap + slack:
            continue
        h = st[S_HEADING, o]
        d = _signed_distance(x, y, rings[k], o, math.cos(h), math.sin(h), st[S_X, o], st[S_Y, o])
        g = d - radius
        if g < gap or g != g:
            gap = g
    return gap


def step_worlds_py(
    active: np.ndarray,
    robot: FloatArray,
    command: FloatArray,
    goal: FloatArray,
    spec: FloatArray,
    counters: np.ndarray,
    status: np.ndarray,
    clearance: FloatArray,
    low: FloatArray,
    n_obs: np.ndarray,
    kind: np.ndarray,
    params: FloatArray,
    state: FloatArray,
    ubuf: FloatArray,
    upos: np.ndarray,
    rings: FloatArray,
) -> None:
    """Advance every ``active`` running world by one decision, in place.

    Per world ``k``: ``robot[k]`` = (x, y, theta) [m, m, rad]; ``command[k]`` = the held (v, u)
    [m/s, rad/s]; ``goal[k]`` [m]; ``spec[k]`` = (radius [m], goal tolerance [m], dt [s]);
    ``counters[k]`` = (step index, steps per decision, steps in the episode); ``status[k]`` (a
    code of :data:`STATUS_NAMES`); ``clearance[k]`` the last step's and ``low[k]`` the smallest
    over this call's steps [m] (``inf`` when none ran).  Obstacles: ``n_obs[k]`` of them in the
    first columns of ``kind`` (K, M), ``params`` (K, P, M), ``state`` (K, S, M), the pre-drawn
    uniforms ``ubuf`` (K, M, B) read from ``upos`` (K, M), and ``rings`` (K, 2, M, W) in their
    body frames.  The caller guarantees ``2 * steps per decision`` unread draws per obstacle.
    """
    for k in range(robot.shape[0]):
        low[k] = math.inf
        if not active[k] or status[k] != RUNNING:
            continue
        dt = spec[k, 2]
        radius, tol = spec[k, 0], spec[k, 1]
        v, u = command[k, 0], command[k, 1]
        for _ in range(counters[k, 1]):
            i = counters[k, 0]
            t = i * dt
            # the robot: unicycle_advance
            x, y, th = robot[k, 0], robot[k, 1], robot[k, 2]
            half = 0.5 * u * dt
            sc = math.pi * (half / math.pi)
            if sc == 0.0:
                sc = _EPS_UNI
            chord = v * dt * (math.sin(sc) / sc)
            x = x + chord * math.cos(th + half)
            y = y + chord * math.sin(th + half)
            robot[k, 0], robot[k, 1], robot[k, 2] = x, y, wrap_angle(th + 2.0 * half)
            for o in range(n_obs[k]):
                _obstacle_step(o, state[k], params[k], kind[k, o], ubuf[k], upos[k], t, dt)
            counters[k, 0] = i = i + 1
            gap = _clearance(k, x, y, radius, n_obs, params, state, rings)
            clearance[k] = gap
            if gap < low[k]:
                low[k] = gap
            if gap < 0.0:
                status[k] = COLLISION
            elif pyhypot(goal[k, 0] - x, goal[k, 1] - y) <= tol:
                status[k] = SUCCESS
            elif i >= counters[k, 2]:
                status[k] = TIMEOUT
            if status[k] != RUNNING:
                break


def lidar_worlds_py(
    active: np.ndarray,
    robot: FloatArray,
    rel: FloatArray,
    max_range: float,
    n_obs: np.ndarray,
    params: FloatArray,
    state: FloatArray,
    rings: FloatArray,
    out: FloatArray,
) -> None:
    """Ranges [m] of :func:`uvnav.sensors.lidar_scan` (no noise) into ``out`` (K, R) for the
    ``active`` worlds: beams at ``wrap(theta + rel)`` [rad], capped at ``max_range`` [m].  A body
    whose bounding disc lies beyond ``max_range`` is skipped: its hits would be farther."""
    n_rays = rel.shape[0]
    for k in range(robot.shape[0]):
        if not active[k]:
            continue
        ox, oy, th = robot[k, 0], robot[k, 1], robot[k, 2]
        for r in range(n_rays):
            out[k, r] = max_range
        st = state[k]
        for o in range(n_obs[k]):
            cx, cy, h = st[S_X, o], st[S_Y, o], st[S_HEADING, o]
            # the cull of ObstacleField.ray_hits (what it casts, this casts too)
            limit = max_range * (1.0 + 1e-9) + 1e-9 * (1.0 + abs(ox) + abs(oy))
            if math.hypot(cx - ox, cy - oy) - params[k, P_BOUND, o] > limit:
                continue
            c, s = math.cos(h), math.sin(h)
            for r in range(n_rays):
                a = wrap_angle(th + rel[r])
                dx, dy = math.cos(a), math.sin(a)
                best = out[k, r]
                rx, ry = rings[k, 0, o, 0], rings[k, 1, o, 0]
                sx, sy = c * rx + s * -ry + cx, c * ry + s * rx + cy
                for j in range(rings.shape[3] - 1):
                    rx, ry = rings[k, 0, o, j + 1], rings[k, 1, o, j + 1]
                    nx, ny = c * rx + s * -ry + cx, c * ry + s * rx + cy
                    ex, ey = nx - sx, ny - sy
                    wx, wy = sx - ox, sy - oy
                    den = dx * ey - dy * ex
                    if abs(den) >= _EPS_RING:
                        tt = (wx * ey - wy * ex) / den
                        ss = (wx * dy - wy * dx) / den
                        if tt >= 0.0 and ss >= 0.0 and ss <= 1.0 and tt < best:
                            best = tt
                    sx, sy = nx, ny
                out[k, r] = best


_KERNELS: dict[str, Callable[..., Any]] = {}
#: the functions compiled, callees before callers
_COMPILED = ("pyhypot", "wrap_angle", "_obstacle_step", "_signed_distance", "_clearance",
             "step_worlds_py", "lidar_worlds_py")  # fmt: skip


def _compile() -> None:
    """Compile the kernels: copies of the Python functions whose globals name the compiled
    callees (the Python functions stay as they are, the reference)."""
    import numba

    env = dict(globals())
    for name in _COMPILED:
        f = globals()[name]
        copy = types.FunctionType(f.__code__, env, name, f.__defaults__, f.__closure__)
        env[name] = numba.njit(cache=True, nogil=True)(copy)
    _KERNELS["step"] = env["step_worlds_py"]
    _KERNELS["lidar"] = env["lidar_worlds_py"]


def kernel(name: str) -> Callable[..., Any]:
    """``"step"`` (:func:`step_worlds_py`) or ``"lidar"`` (:func:`lidar_worlds_py`), compiled by
    numba on first use when it is enabled (:func:`numba_enabled`), else the Python functions."""
    if not numba_enabled():
        return step_worlds_py if name == "step" else lidar_worlds_py
    if not _KERNELS:
        _compile()
    return _KERNELS[name]


def pack_check(setup: EpisodeSetup) -> str | None:
    """Why ``setup`` cannot be packed (one line), or None: a unicycle among polygon bodies with
    :class:`ConstantVelocity` or :class:`RandomTurn` motion."""
    if type(setup.spec) is not UnicycleSpec:
        return f"the robot is a {type(setup.spec).__name__}, packed worlds hold unicycles"
    for j, ob in enumerate(setup.obstacles):
        if not isinstance(ob.body, PolygonBody):
            return f"obstacle {j} is a {type(ob.body).__name__}, packed worlds hold polygons"
        if type(ob.motion) not in (ConstantVelocity, RandomTurn):
            return (
                f"obstacle {j} moves by {type(ob.motion).__name__}, packed worlds hold "
                "constant-velocity and random-turn motion"
            )
    return None


class PackedWorlds:
    """``k`` slots of packed worlds (module docstring); :meth:`load` an episode into a slot,
    :meth:`step` all running ones by one decision.

    The arrays are public and are the state (see :func:`step_worlds_py` for their layout); a
    slot's obstacles keep their generators, read ahead by up to :data:`BLOCK` numbers, so the
    :class:`RandomTurn` models are not written back (unlike :meth:`UnicycleWorld.close`).
    """

    def __init__(self, k: int) -> None:
        self.k = int(k)
        self.robot = np.zeros((k, 3))
        self.command = np.zeros((k, 2))
        self.goal = np.zeros((k, 2))
        self.spec = np.zeros((k, 3))
        self.limits = np.zeros((k, 2))  # v_max [m/s], u_max [rad/s]
        self.counters = np.zeros((k, 3), dtype=np.int64)
        self.status = np.full(k, TIMEOUT, dtype=np.int64)
        self.clearance = np.full(k, math.inf)
        self.low = np.full(k, math.inf)
        self.n_obs = np.zeros(k, dtype=np.int64)
        self.rngs: list[list[np.random.Generator | None]] = [[] for _ in range(k)]
        self._alloc(0, 2)

    def _alloc(self, m: int, w: int) -> None:
        """(Re)allocate the obstacle arrays for ``m`` obstacles of ``w``-column rings, keeping
        what the slots hold."""
        k = self.k
        old = getattr(self, "kind", None)
        kind = np.full((k, m), EMPTY, dtype=np.int64)
        params = np.zeros((k, N_PARAMS, m))
        state = np.zeros((k, N_STATE, m))
        ubuf = np.zeros((k, m, BLOCK))
        upos = np.zeros((k, m), dtype=np.int64)
        rings = np.zeros((k, 2, m, w))
        if old is not None:
            m0, w0 = self.rings.shape[2], self.rings.shape[3]
            kind[:, :m0] = self.kind
            params[:, :, :m0] = self.params
            state[:, :, :m0] = self.state
            ubuf[:, :m0] = self.ubuf
            upos[:, :m0] = self.upos
            rings[:, :, :m0, :w0] = self.rings
            rings[:, :, :m0, w0:] = self.rings[:, :, :, :1]  # more copies of the first vertex
        self.kind, self.params, self.state = kind, params, state
        self.ubuf, self.upos, self.rings = ubuf, upos, rings

    def load(self, slot: int, setup: EpisodeSetup) -> None:
        """Put ``setup``'s episode in ``slot`` as :meth:`UnicycleWorld.start` begins it (status,
        clearance at t = 0).

        Raises:
            ValueError: the episode cannot be packed (:func:`pack_check`).
        """
        why = pack_check(setup)
        if why is not None:
            raise ValueError(why)
        obstacles = setup.obstacles
        m = len(obstacles)
        tpl = FieldTemplate.from_bodies([o.body for o in obstacles])
        w = tpl.rings.shape[2] if m else 2
        if m > self.rings.shape[2] or w > self.rings.shape[3]:
            self._alloc(max(m, self.rings.shape[2]), max(w, self.rings.shape[3]))
        spec = setup.spec
        dt = float(setup.dt)
        self.robot[slot] = np.asarray(setup.start, dtype=float)[:3]
        self.command[slot] = 0.0
        self.goal[slot] = np.asarray(setup.goal, dtype=float)[:2]
        self.spec[slot] = (float(spec.radius), float(setup.goal_tolerance), dt)
        self.limits[slot] = (float(spec.v_max), float(spec.u_max))
        n_steps = round(setup.t_max / dt)
        self.counters[slot] = (0, decision_ratio(float(setup.control_period), dt), n_steps)
        self.n_obs[slot] = m
        self.kind[slot] = EMPTY
        self.rings[slot] = 0.0
        if m:
            self.rings[slot, :, :m, :w] = tpl.rings
            self.rings[slot, :, :m, w:] = tpl.rings[:, :, :1]
        self.rngs[slot] = [self._pack_obstacle(slot, o, ob) for o, ob in enumerate(obstacles)]
        self.params[slot, P_BOUND, :m] = tpl.bounding_radii
        x, y = float(self.robot[slot, 0]), float(self.robot[slot, 1])
        gap = _clearance(slot, x, y, float(spec.radius), self.n_obs, self.params, self.state,
                         self.rings)  # fmt: skip
        self.clearance[slot] = gap
        status = RUNNING
        if gap < 0:
            status = COLLISION
        elif math.hypot(self.goal[slot, 0] - x, self.goal[slot, 1] - y) <= setup.goal_tolerance:
            status = SUCCESS
        elif n_steps <= 0:
            status = TIMEOUT
        self.status[slot] = status

    def _pack_obstacle(self, slot: int, o: int, ob: Obstacle) -> np.random.Generator | None:
        """Obstacle ``o`` of ``slot``: its state, parameters and first block of draws."""
        st, prm, mod = self.state[slot], self.params[slot], ob.motion
        state = ob.state
        st[:, o] = 0.0
        prm[:, o] = 0.0
        st[S_X, o], st[S_Y, o] = state.position
        st[S_HEADING, o] = state.heading
        if isinstance(mod, ConstantVelocity):
            self.kind[slot, o] = CONSTANT
            prm[P_VX, o], prm[P_VY, o] = np.asarray(mod.velocity, dtype=float)
            prm[P_OMEGA, o] = float(mod.angular_velocity)
            return None
        assert isinstance(mod, RandomTurn)
        self.kind[slot, o] = RANDOM_TURN
        if mod.course is None:  # as ObstacleBatch does
            vel = state.velocity
            course = float(np.arctan2(vel[1], vel[0])) if np.hypot(*vel) > 0 else state.heading
        else:
            course = mod.course
        st[S_COURSE, o] = course
        st[S_SPEED, o], st[S_TURN, o] = mod._speed, mod._turn
        st[S_NEXT, o] = mod._next_change
        st[S_THRESHOLD, o] = mod._next_change - 1e-12
        for lo_row, span_row, bounds in (
            (P_SPEED_LO, P_SPEED_SPAN, mod.speed),
            (P_TURN_LO, P_TURN_SPAN, mod.turn_rate),
        ):
            lo = float(bounds[0])
            span = float(bounds[1]) - lo
            if not (math.isfinite(span) and span >= 0.0):
                raise ValueError(f"random-turn bounds {tuple(bounds)} are not (low, high)")
            prm[lo_row, o], prm[span_row, o] = lo, span
        prm[P_PERIOD, o] = float(mod.change_period)
        prm[P_SPIN, o] = float(mod.spin)
        prm[P_LIMIT, o] = max(abs(mod.turn_rate[0]), abs(mod.turn_rate[1]))
        if mod.arena is not None:
            x0, y0, x1, y1 = mod.arena
            prm[P_ARENA, o] = 1.0
            prm[P_X0, o], prm[P_Y0, o], prm[P_X1, o], prm[P_Y1, o] = x0, y0, x1, y1
            prm[P_MIDX, o], prm[P_MIDY, o] = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        self.ubuf[slot, o] = mod.rng.random(BLOCK)
        self.upos[slot, o] = 0
        return mod.rng

    def refill(self) -> None:
        """Top up the draws of every obstacle that may need more in the next decision (two per
        integration step): the unread ones move to the front, the rest are drawn."""
        need = 2 * self.counters[:, 1:2]
        for slot, o in zip(*(self.upos + need > BLOCK).nonzero(), strict=True):
            rng = self.rngs[slot][o]
            if rng is None:
                continue
            p = int(self.upos[slot, o])
            left = BLOCK - p
            self.ubuf[slot, o, :left] = self.ubuf[slot, o, p:]
            self.ubuf[slot, o, left:] = rng.random(p)
            self.upos[slot, o] = 0

    def step(self, active: np.ndarray | None = None) -> None:
        """Advance every running world (of the ``active`` (k,) bool slots) by one decision with
        the commands in :attr:`command` ((v, u) [m/s, rad/s], held as given)."""
        if active is None:
            active = np.ones(self.k, dtype=np.bool_)
        self.refill()
        kernel("step")(
            active, self.robot, self.command, self.goal, self.spec, self.counters, self.status,
            self.clearance, self.low, self.n_obs, self.kind, self.params, self.state, self.ubuf,
            self.upos, self.rings,
        )  # fmt: skip

    def lidar(self, rel: FloatArray, max_range: float, out: FloatArray) -> FloatArray:
        """The noise-free lidar ranges [m] of every slot into ``out`` (k, len(rel)): beams at
        heading + ``rel`` [rad] (:func:`uvnav.sensors.lidar_scan`'s)."""
        kernel("lidar")(
            np.ones(self.k, dtype=np.bool_), self.robot, rel, float(max_range), self.n_obs,
            self.params, self.state, self.rings, out,
        )  # fmt: skip
        return out
