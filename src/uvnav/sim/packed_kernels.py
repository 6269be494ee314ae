"""The compiled world kernels of :mod:`uvnav.sim.packed`: the arrays' layout, the obstacles'
motion, the exact clearance and the step of every world by one decision.

Each function here is plain Python that numba compiles (:func:`uvnav.sim.packed.kernel`); the
numbers are those :mod:`uvnav.sim.packed`'s docstring lists, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np

from uvnav.dynamics.unicycle import unicycle_advance
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.polygons import ring_nearest_py
from uvnav.geometry.small import pyhypot

#: status codes of a packed world
RUNNING, SUCCESS, COLLISION, TIMEOUT = 0, 1, 2, 3
STATUS_NAMES = ("running", "success", "collision", "timeout")
#: motion kinds of a packed obstacle (-1: an empty slot)
EMPTY, CONSTANT, RANDOM_TURN = -1, 0, 1
#: random numbers are pre-drawn per obstacle in rows of ROW_BLOCKS blocks of BLOCK (longer rows
#: where one decision may need more); a row is topped up once half of it has been read
BLOCK = 64
ROW_BLOCKS = 4

# Columns of the (K, NW) float array of the worlds: pose [m, m, rad], held command [m/s, rad/s],
# goal [m], robot radius [m], goal tolerance [m], dt [s], clearance now and lowest over the last
# decision [m], V_max [m/s], U_max [rad/s].
(W_X, W_Y, W_TH, W_V, W_U, W_GX, W_GY, W_RADIUS, W_TOL, W_DT, W_CLEAR, W_LOW, W_VMAX,
 W_UMAX) = range(14)  # fmt: skip
NW = 14
# Columns of the (K, NI) int array of the worlds: step index, steps per decision, steps in the
# episode, status code, number of obstacles, 1 when the next step() advances it.
I_STEP, I_RATIO, I_NSTEPS, I_STATUS, I_NOBS, I_ACTIVE = range(6)
NI = 6
# Rows of the (K, 2, M) int array of the obstacles: motion kind, next unread pre-drawn number.
O_KIND, O_UPOS = 0, 1
# Parameter rows of the (K, P, M) obstacle parameter array.
(P_VX, P_VY, P_OMEGA, P_SPEED_LO, P_SPEED_SPAN, P_TURN_LO, P_TURN_SPAN, P_PERIOD, P_SPIN,
 P_X0, P_Y0, P_X1, P_Y1, P_MIDX, P_MIDY, P_LIMIT, P_ARENA, P_BOUND) = range(18)  # fmt: skip
N_PARAMS = 18
# State rows of the (K, S, M) obstacle state array (the velocity and rotation rate are those
# used over the last step, as :class:`ObstacleBatch` reports them).
(S_X, S_Y, S_HEADING, S_COURSE, S_SPEED, S_TURN, S_NEXT, S_THRESHOLD, S_VX, S_VY,
 S_OMEGA) = range(11)  # fmt: skip
N_STATE = 11


def _move_obstacles(k: int, n: int, state: FloatArray, params: FloatArray, oi: np.ndarray,
                    ubuf: FloatArray, t: float, dt: float) -> None:  # fmt: skip
    """Advance obstacles ``0..n-1`` of world ``k`` (``state`` (K, S, M), ``params`` (K, P, M),
    ``oi`` (K, 2, M), ``ubuf`` (K, M, B)) from ``t`` by ``dt`` [s]: :class:`ObstacleBatch`'s
    arithmetic.

    One call moves them all, and takes the packed arrays whole: a compiled call that takes
    arrays passes each one as a struct and counts references to it, about 35 ns for the four
    arrays here, more than a random-turn step itself (about 25 ns) when it was made once per
    obstacle, and slicing them per world costs more."""
    for o in range(n):
        kind = oi[k, O_KIND, o]
        if kind == CONSTANT:
            state[k, S_HEADING, o] = wrap_scalar(
                state[k, S_HEADING, o] + params[k, P_OMEGA, o] * dt
            )
            state[k, S_X, o] = state[k, S_X, o] + params[k, P_VX, o] * dt
            state[k, S_Y, o] = state[k, S_Y, o] + params[k, P_VY, o] * dt
            state[k, S_VX, o], state[k, S_VY, o], state[k, S_OMEGA, o] = (
                params[k, P_VX, o],
                params[k, P_VY, o],
                params[k, P_OMEGA, o],
            )
            continue
        if t >= state[k, S_THRESHOLD, o]:  # a new speed and turn rate (RandomTurn.step's two draws)
            p = oi[k, O_UPOS, o]
            state[k, S_SPEED, o] = (
                params[k, P_SPEED_LO, o] + params[k, P_SPEED_SPAN, o] * ubuf[k, o, p]
            )
            state[k, S_TURN, o] = (
                params[k, P_TURN_LO, o] + params[k, P_TURN_SPAN, o] * ubuf[k, o, p + 1]
            )
            oi[k, O_UPOS, o] = p + 2
            nc = t + params[k, P_PERIOD, o]
            state[k, S_NEXT, o] = nc
            state[k, S_THRESHOLD, o] = nc - 1e-12
        turn = state[k, S_TURN, o]
        px, py = state[k, S_X, o], state[k, S_Y, o]
        if params[k, P_ARENA, o] > 0.0 and not (
            params[k, P_X0, o] <= px <= params[k, P_X1, o]
            and params[k, P_Y0, o] <= py <= params[k, P_Y1, o]
        ):  # outside its arena: turn back toward the centre at the largest rate
            to_c = math.atan2(params[k, P_MIDY, o] - py, params[k, P_MIDX, o] - px)
            lim = params[k, P_LIMIT, o]
            turn = min(max(wrap_scalar(to_c - state[k, S_COURSE, o]) / dt, -lim), lim)
        om = turn + params[k, P_SPIN, o]
        course = wrap_scalar(state[k, S_COURSE, o] + turn * dt)
        state[k, S_HEADING, o] = wrap_scalar(state[k, S_HEADING, o] + om * dt)
        state[k, S_COURSE, o] = course
        mid = course - 0.5 * turn * dt
        speed = state[k, S_SPEED, o]
        vx, vy = math.cos(mid) * speed, math.sin(mid) * speed
        state[k, S_X, o] = px + vx * dt
        state[k, S_Y, o] = py + vy * dt
        state[k, S_VX, o], state[k, S_VY, o], state[k, S_OMEGA, o] = vx, vy, om


def _transform_ring(rings: FloatArray, o: int, c: float, s: float, cx: float, cy: float,
                    out: FloatArray) -> None:  # fmt: skip
    """Ring ``o`` of ``rings`` (2, M, W) turned by (``c``, ``s``) = (cos, sin) of its heading and
    moved to ``(cx, cy)`` [m], into ``out`` (2, W): :func:`transform_rings`'s operations."""
    for j in range(rings.shape[2]):
        rx, ry = rings[0, o, j], rings[1, o, j]
        out[0, j] = c * rx + s * -ry + cx
        out[1, j] = c * ry + s * rx + cy


def _clearance(k: int, x: float, y: float, radius: float, n_obs: int, params: FloatArray,
               state: FloatArray, rings: FloatArray, ring: FloatArray,
               low: FloatArray) -> tuple[float, int]:  # fmt: skip
    """Exact clearance [m] of the robot disc at ``(x, y)`` in world ``k`` (``params`` (K, P,
    M), ``state`` (K, S, M), ``rings`` (K, 2, M, W), taken whole as :func:`_move_obstacles`
    takes them; ``ring`` (2, W) and ``low`` (M,) scratch): the signed distance
    of :meth:`ObstacleField.query` (boundary distance outside, minus it inside) minus the
    radius, and the obstacle it is to (the first in index order on a tie, as the field's
    ``argmin``); ``(inf, -1)`` without obstacles.

    A broad phase skips the bodies that cannot lower the minimum, in two passes: a lower bound
    of every body's gap (centre distance minus bounding radius minus the robot's radius), then
    the exact gap of the body with the lowest bound first and of every other body whose bound
    does not exceed the gap found so far.  Starting from the likely nearest body, a step of
    the benchmark's worlds computes about one exact gap (scanning in index order computed 3.3
    of 10, 5.9 of 100).  A bound is ``sqrt(dx^2 + dy^2) (1 - 1e-9)``: libm's ``hypot`` costs
    twice as much, and the relative margin covers the few ulps between them, as the absolute
    ``slack`` covers the rounding of the transformed rings (the :meth:`ObstacleField.query`
    cull's margins); a distance whose square is not below 1e300 takes ``hypot``.  The kept
    bodies' gaps have the same arithmetic as before, and the first lowest one in index order
    is returned, as the scan in index order returned it (it matters only for ``-0.0``)."""
    if n_obs == 0:
        return math.inf, -1
    slack = 1e-9 * (1.0 + abs(x) + abs(y))
    first, best = 0, math.inf
    for o in range(n_obs):
        dx, dy = state[k, S_X, o] - x, state[k, S_Y, o] - y
        dd = dx * dx + dy * dy
        dc = math.sqrt(dd) if dd < 1e300 else math.hypot(dx, dy)
        bound = dc * (1.0 - 1e-9) - params[k, P_BOUND, o] - radius
        low[o] = bound
        if bound < best:
            first, best = o, bound
    gap, at = math.inf, n_obs
    for j in range(-1, n_obs):
        o = first if j < 0 else j
        if j == first or low[o] > gap + slack:
            continue  # done first, or its bounding disc is farther than the gap so far
        h, cx, cy = state[k, S_HEADING, o], state[k, S_X, o], state[k, S_Y, o]
        c, s = math.cos(h), math.sin(h)
        for j in range(ring.shape[1]):  # _transform_ring's operations, inlined
            rx, ry = rings[k, 0, o, j], rings[k, 1, o, j]
            ring[0, j] = c * rx + s * -ry + cx
            ring[1, j] = c * ry + s * rx + cy
        d, qx, qy, inside = ring_nearest_py(x, y, ring[0], ring[1], True)
        if inside:
            d = -float(np.hypot(qx - x, qy - y))  # numpy's (libm's), as the field's depth
        g = d - radius
        if g < gap or g != g or (g == gap and o < at):
            gap, at = g, o
    return gap, (at if at < n_obs else -1)


def step_worlds_py(
    wf: FloatArray,
    wi: np.ndarray,
    oi: np.ndarray,
    params: FloatArray,
    state: FloatArray,
    ubuf: FloatArray,
    rings: FloatArray,
) -> int:
    """Advance every active running world by one decision (``wi[k, I_RATIO]`` integration
    steps), in place; return how many more calls the pre-drawn numbers cover (at two a step).

    The worlds' floats ``wf`` (K, NW) and ints ``wi`` (K, NI) are laid out as the ``W_*`` and
    ``I_*`` columns say; obstacle ``o`` < ``wi[k, I_NOBS]`` of world ``k`` has its motion kind
    and next unread draw in ``oi[k, :, o]``, its parameters ``params[k, :, o]`` (``P_*``), its
    state ``state[k, :, o]`` (``S_*``), its pre-drawn uniforms ``ubuf[k, o]`` and its body
    ring ``rings[k, :, o]`` (body frame).  The caller guarantees two unread draws per step.

    The count returned spares :meth:`PackedWorlds.step` numpy's per-call costs (about 5 µs)
    when it asks whether a top-up is due."""
    ring = np.empty((2, rings.shape[3]))
    low = np.empty(rings.shape[2])
    for k in range(wf.shape[0]):
        wf[k, W_LOW] = math.inf
        if wi[k, I_ACTIVE] == 0 or wi[k, I_STATUS] != RUNNING:
            continue
        dt = wf[k, W_DT]
        radius, tol = wf[k, W_RADIUS], wf[k, W_TOL]
        v, u = wf[k, W_V], wf[k, W_U]
        for _ in range(wi[k, I_RATIO]):
            i = wi[k, I_STEP]
            t = i * dt
            x, y, th = unicycle_advance(wf[k, W_X], wf[k, W_Y], wf[k, W_TH], v, u, dt)
            wf[k, W_X], wf[k, W_Y], wf[k, W_TH] = x, y, th
            _move_obstacles(k, wi[k, I_NOBS], state, params, oi, ubuf, t, dt)
            wi[k, I_STEP] = i = i + 1
            gap, _ = _clearance(k, x, y, radius, wi[k, I_NOBS], params, state, rings, ring,
                                low)  # fmt: skip
            wf[k, W_CLEAR] = gap
            if gap < wf[k, W_LOW]:
                wf[k, W_LOW] = gap
            if gap < 0.0:
                wi[k, I_STATUS] = COLLISION
            elif pyhypot(wf[k, W_GX] - x, wf[k, W_GY] - y) <= tol:
                wi[k, I_STATUS] = SUCCESS
            elif i >= wi[k, I_NSTEPS]:
                wi[k, I_STATUS] = TIMEOUT
            if wi[k, I_STATUS] != RUNNING:
                break
    safe = 1 << 40
    for k in range(wf.shape[0]):
        read = 0
        for o in range(wi[k, I_NOBS]):
            read = max(read, oi[k, O_UPOS, o])
        safe = min(safe, (ubuf.shape[2] - read) // (2 * max(wi[k, I_RATIO], 1)))
    return safe


def clearance_one_py(x: float, y: float, radius: float, n_obs: int, prm: FloatArray,
                     st: FloatArray, rings: FloatArray) -> tuple[float, int]:  # fmt: skip
    """:func:`_clearance` of the robot disc of ``radius`` [m] at ``(x, y)`` among the ``n_obs``
    obstacles of one world as they stand (one slot's ``params``, ``state`` and ``rings``), with
    its own scratch: :meth:`ObstacleField.query`'s signed distance minus the radius [m] and the
    nearest obstacle (-1 without any), without building the field."""
    ring = np.empty((2, rings.shape[2]))
    low = np.empty(rings.shape[1])
    return _clearance(0, x, y, radius, n_obs, prm[None], st[None], rings[None], ring, low)


# numpy's SeedSequence constants (hash and mix multipliers) and PCG64's multiplier
_M32 = 0xFFFFFFFF
_INIT_A, _MULT_A, _INIT_B, _MULT_B = 0x43B0D7E5, 0x931E8875, 0x8B51F9DD, 0x58F38DED
_MIX_L, _MIX_R = 0xCA01F9DD, 0x4973F715


def _hashmix(value: int, hc: int) -> tuple[int, int]:
    """SeedSequence's ``hashmix`` of ``value`` with hash constant ``hc`` (32-bit words held in
    int64, products wrapping): the mixed value and the next constant."""
    value ^= hc
    hc = (hc * _MULT_A) & _M32
    value = (value * hc) & _M32
    return value ^ (value >> 16), hc


def _mix(x: int, y: int) -> int:
    """SeedSequence's ``mix`` of two 32-bit words (held in int64, products wrapping)."""
    r = (_MIX_L * x - _MIX_R * y) & _M32
    return r ^ (r >> 16)


def spawn_words_py(entropy: np.ndarray, out: np.ndarray) -> None:
    """The first 8 32-bit words of ``generate_state`` (as int64, low word of each uint64 first)
    of the children ``c`` < ``out.shape[0]`` that ``numpy.random.SeedSequence.spawn`` makes of
    a sequence whose run entropy, as 32-bit words padded with zeros to the pool size 4, is
    ``entropy`` (E,) int64: the children's spawn keys ``(c,)`` mixed in after it, numpy's
    operations on the words.  What a :class:`numpy.random.PCG64` seeded by child ``c`` takes as
    its state and increment."""
    n_ent = entropy.shape[0]
    mixer = np.zeros(4, dtype=np.int64)
    for c in range(out.shape[0]):
        hc = _INIT_A
        for i in range(4):
            mixer[i], hc = _hashmix(int(entropy[i]), hc)
        for src in range(4):
            for dst in range(4):
                if src != dst:
                    v, hc = _hashmix(int(mixer[src]), hc)
                    mixer[dst] = _mix(int(mixer[dst]), v)
        for src in range(4, n_ent + 1):  # the run entropy's tail, then the spawn key
            word = int(entropy[src]) if src < n_ent else c
            for dst in range(4):
                v, hc = _hashmix(word, hc)
                mixer[dst] = _mix(int(mixer[dst]), v)
        hb = _INIT_B
        for j in range(8):
            v = int(mixer[j % 4]) ^ hb
            hb = (hb * _MULT_B) & _M32
            v = (v * hb) & _M32
            out[c, j] = v ^ (v >> 16)


# PCG64's multiplier in two words, and the constants of the 128-bit arithmetic, as uint64
_PM_HI, _PM_LO = np.uint64(2549297995355413924), np.uint64(4865540595714422341)
_U32, _U0, _U1 = np.uint64(0xFFFFFFFF), np.uint64(0), np.uint64(1)
_SH11, _SH32, _SH58, _SH63, _SH64 = (np.uint64(11), np.uint64(32), np.uint64(58), np.uint64(63),
                                     np.uint64(64))  # fmt: skip
_TO_UNIT = 1.0 / 9007199254740992.0


def _mulhi(a: np.uint64, b: np.uint64) -> np.uint64:
    """The high word of the 128-bit product of two uint64 words."""
    a0, a1, b0, b1 = a & _U32, a >> _SH32, b & _U32, b >> _SH32
    p00, p01, p10 = a0 * b0, a0 * b1, a1 * b0
    mid = (p00 >> _SH32) + (p01 & _U32) + (p10 & _U32)
    return a1 * b1 + (p01 >> _SH32) + (p10 >> _SH32) + (mid >> _SH32)


def _pcg_step(hi: np.uint64, lo: np.uint64, inc_hi: np.uint64,
              inc_lo: np.uint64) -> tuple[np.uint64, np.uint64]:  # fmt: skip
    """PCG64's state advance (state x multiplier + increment, mod 2^128) on two words each."""
    t = lo * _PM_LO
    new_lo = t + inc_lo
    carry = _U1 if new_lo < t else _U0
    new_hi = _mulhi(lo, _PM_LO) + hi * _PM_LO + lo * _PM_HI + inc_hi + carry
    return new_hi, new_lo


def spawn_fill_py(entropy: np.ndarray, kinds: np.ndarray, rows: FloatArray,
                  pcg: np.ndarray) -> None:  # fmt: skip
    """Seed the ``n`` = ``pcg.shape[0]`` PCG64 generators of ``SeedSequence.spawn(n)`` of a run
    entropy ``entropy`` (:func:`spawn_words_py`'s) and fill row ``c`` of ``rows`` (M, B) with
    child ``c``'s first B ``Generator.random()`` numbers where ``kinds[c]`` is
    :data:`RANDOM_TURN`: numpy's ``pcg64_set_seed`` and ``next_double`` (the XSL-RR output of
    each advanced state, its top 53 bits over 2^53), bit for bit.  Each generator's state after
    its draws goes to ``pcg[c]`` (uint64: state high and low words, increment high and low)."""
    n = pcg.shape[0]
    words = np.empty((n, 8), dtype=np.int64)
    spawn_words_py(entropy, words)
    for c in range(n):
        w = words[c]
        s_hi = (np.uint64(w[1]) << _SH32) | np.uint64(w[0])
        s_lo = (np.uint64(w[3]) << _SH32) | np.uint64(w[2])
        q_hi = (np.uint64(w[5]) << _SH32) | np.uint64(w[4])
        q_lo = (np.uint64(w[7]) << _SH32) | np.uint64(w[6])
        inc_hi = (q_hi << _U1) | (q_lo >> _SH63)
        inc_lo = (q_lo << _U1) | _U1
        lo = inc_lo + s_lo  # state 0 advanced (the increment), plus the seed
        hi = inc_hi + s_hi + (_U1 if lo < inc_lo else _U0)
        hi, lo = _pcg_step(hi, lo, inc_hi, inc_lo)
        if kinds[c] == RANDOM_TURN:
            for j in range(rows.shape[1]):
                hi, lo = _pcg_step(hi, lo, inc_hi, inc_lo)
                x = hi ^ lo
                rot = hi >> _SH58
                x = (x >> rot) | (x << ((_SH64 - rot) & _SH63))
                rows[c, j] = float(x >> _SH11) * _TO_UNIT
        pcg[c, 0], pcg[c, 1], pcg[c, 2], pcg[c, 3] = hi, lo, inc_hi, inc_lo


def restore_many_py(slots: np.ndarray, seeds: np.ndarray, key: int, img_wf: FloatArray,
                    img_wi: np.ndarray, img_oi: np.ndarray, img_params: FloatArray,
                    img_state: FloatArray, img_rings: FloatArray, wf: FloatArray,
                    wi: np.ndarray, oi: np.ndarray, params: FloatArray, state: FloatArray,
                    rings: FloatArray, read: np.ndarray, ubuf: FloatArray,
                    pcg: np.ndarray) -> None:  # fmt: skip
    """Put one slot's image (``img_*``: its rows of the packed arrays) in each slot
    ``slots[i]``, no draws read, with its obstacles' rows of draws filled by
    :func:`spawn_fill_py` from the run entropy ``[seeds[i], key]`` (``0 <= seeds[i] < 2^63``,
    ``0 <= key < 2^32``; the generators' states after the draws into ``pcg[i]``):
    :meth:`PackedWorlds.restore_spawned_many <uvnav.sim.packed.PackedWorlds>` in one call."""
    words = np.zeros(4, dtype=np.int64)
    for i in range(slots.shape[0]):
        s = slots[i]
        wf[s] = img_wf
        wi[s] = img_wi
        oi[s] = img_oi
        params[s] = img_params
        state[s] = img_state
        rings[s] = img_rings
        read[s] = 0
        lo, hi = seeds[i] & _M32, seeds[i] >> 32  # entropy_words([seeds[i], key])
        words[0], words[1], words[2], words[3] = (lo, key, 0, 0) if hi == 0 else (lo, hi, key, 0)
        spawn_fill_py(words, img_oi[O_KIND], ubuf[s], pcg[i])
