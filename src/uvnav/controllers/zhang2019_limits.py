"""The unicycle of ``zhang2019-v2`` under acceleration limits: the commands it can reach within a
decision period (a dynamic window), the turn law that brakes its turn in time, and the path the
vehicle follows toward a candidate, checked against moving discs
(:mod:`uvnav.controllers.zhang2019_v2`, module docstring, "Acceleration limits").

The vehicle (:class:`uvnav.dynamics.unicycle.Unicycle`) moves its speed and turn rate toward the
held command by at most ``accel_max dt`` and ``turn_accel_max dt`` per integration step.  The
law holds each command for one decision period T; :func:`rollout` plays the law's own steering
(:func:`speed_command`, :func:`turn_command`) toward a fixed aim, decision after decision, on
that vehicle, and :func:`path_risk` checks the resulting path, a chain of straight segments, in
closed form per segment.  Units: metres, seconds, radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from uvnav.controllers.holonomic import toward_goal
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.contact import first_contact, forecast_gap

#: a mask, one entry per path
BoolArray = npt.NDArray[np.bool_]


@dataclass(frozen=True)
class RampModel:
    """What the law knows of its vehicle and its own clock.

    Attributes:
        v_max: V_max [m/s].
        u_max: U_max [rad/s].
        accel: largest speed change [m/s^2] (``inf``: at once).
        turn_accel: largest turn-rate change [rad/s^2] (``inf``: at once).
        period: the decision period T [s] a command is held for.
        turn_first: the vehicle turns by the period's turn at each decision, then moves
            straight (``turn-then-move`` kinematics, :func:`uvnav.dynamics.unicycle.ramp_turn`);
            ``False``: it turns along arcs.
    """

    v_max: float
    u_max: float
    accel: float
    turn_accel: float
    period: float
    turn_first: bool = False

    @property
    def ideal(self) -> bool:
        """The speed and the turn rate follow the command at once (both limits infinite), as
        :attr:`uvnav.dynamics.unicycle.UnicycleSpec.ideal` of the spec it was made from.

        >>> RampModel(1.0, 1.0, math.inf, math.inf, 0.25).ideal, RampModel(1.0, 1.0, 1.0,
        ...     math.inf, 0.25).ideal
        (True, False)
        """
        return math.isinf(self.accel) and math.isinf(self.turn_accel)

    def window(self, now: FloatArray | float, rate: float, low: float, high: float) -> FloatArray:
        """The values reachable from ``now`` within one period at ``rate`` per second, clipped to
        [``low``, ``high``]: ``(lo, hi)`` arrays."""
        now = np.asarray(now, dtype=float)
        step = rate * self.period
        return np.asarray([np.clip(now - step, low, high), np.clip(now + step, low, high)])


def approach(value: FloatArray, target: FloatArray, most: float) -> FloatArray:
    """``value`` moved toward ``target`` by at most ``most`` (>= 0), elementwise (as the vehicle
    does, :func:`uvnav.dynamics.unicycle.approach`)."""
    if math.isinf(most):
        return np.asarray(target, dtype=float)
    return np.asarray(value + np.clip(target - value, -most, most), dtype=float)


def ramp_turns(u_now: FloatArray, target: FloatArray, rate: float, period: float) -> FloatArray:
    """:func:`uvnav.dynamics.unicycle.ramp_turn` elementwise, the same to the bit: the heading
    change [rad] over ``period`` of turn rates moving from ``u_now`` toward ``target`` at
    ``rate`` [rad/s^2].

    >>> ramp_turns(np.zeros(2), np.array([1.0, 0.2]), 2.0, 0.25).round(6).tolist()
    [0.0625, 0.04]
    """
    u_now, target = np.asarray(u_now, dtype=float), np.asarray(target, dtype=float)
    if math.isinf(rate):
        return np.asarray(target * period, dtype=float)
    gap = target - u_now
    ramp = np.minimum(np.abs(gap) / rate, period)
    u_end = u_now + np.copysign(rate * ramp, gap)
    return np.asarray(np.where(ramp < period, 0.5 * (u_now + u_end) * ramp
                               + target * (period - ramp), 0.5 * (u_now + u_end) * period),
                      dtype=float)  # fmt: skip


def speed_command(target: FloatArray, v_now: FloatArray, model: RampModel) -> FloatArray:
    """The speed [m/s] to command: ``target`` within [0, V_max] and within the window of speeds
    reachable from ``v_now`` in one period."""
    lo, hi = model.window(v_now, model.accel, 0.0, model.v_max)
    return np.asarray(np.clip(target, lo, hi), dtype=float)


def turn_command(beta: FloatArray, u_now: FloatArray, model: RampModel) -> FloatArray:
    """The turn rate [rad/s] to command toward a heading error ``beta`` [rad]: the sliding-mode
    law with its boundary layer (``beta / T`` within it, U_max beyond), no faster than a turn
    that can still be stopped at ``beta`` = 0 — ``u^2 / (2 B) + u T / 2 <= |beta|`` (B the turn
    acceleration; the turn runs on for about half a period before the next decision brakes it)
    — and within the window of rates reachable from ``u_now`` in one period.

    >>> m = RampModel(1.0, 3.0, 1.0, 2.0, 0.25)
    >>> turn_command(np.array([1.0]), np.array([0.0]), m).tolist()  # the window: +-0.5 rad/s
    [0.5]
    >>> round(float(turn_command(np.array([0.1]), np.array([2.0]), m)[0]), 6)  # brake the turn
    1.5
    """
    b = np.abs(np.asarray(beta, dtype=float))
    mag = np.minimum(b / model.period, model.u_max)
    a = model.turn_accel
    if math.isfinite(a):
        half = 0.5 * a * model.period
        mag = np.minimum(mag, np.sqrt(half * half + 2.0 * a * b) - half)
    lo, hi = model.window(u_now, a, -model.u_max, model.u_max)
    return np.asarray(np.clip(np.sign(beta) * mag, lo, hi), dtype=float)


def rollout(
    pose: FloatArray,
    v_now: float,
    u_now: float,
    aim: FloatArray,
    speed: FloatArray,
    model: RampModel,
    horizon: float,
    step: float,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The paths of the robot steering toward each aim direction ``aim`` (K,) [rad] at the
    speeds ``speed`` (K,) [m/s] for ``horizon`` [s], from ``pose`` ``[x, y, theta]`` at speed
    ``v_now`` and turn rate ``u_now``: ``(times (S + 1,), positions (K, S + 1, 2), speeds
    (K, S + 1))``.

    At every decision (each period T) the law commands ``speed cos(beta)`` (0 for an aim behind)
    and :func:`turn_command`, both within the window; between decisions the vehicle moves its
    speed and turn rate toward them at its limits, in substeps of at most ``step`` [s], each
    integrated on its arc at the substep's mean speed and turn rate; a ``turn_first`` vehicle
    instead turns by the period's ramped turn at the decision and moves straight.

    >>> m = RampModel(1.0, 1.0, 1.0, math.inf, 0.25)
    >>> t, xy, v = rollout(np.zeros(3), 0.0, 0.0, np.zeros(1), np.ones(1), m, 1.0, 0.25)
    >>> np.round(xy[0, :, 0], 6).tolist()  # from rest at 1 m/s^2: x = t^2 / 2
    [0.0, 0.03125, 0.125, 0.28125, 0.5]
    """
    n_sub = max(1, math.ceil(model.period / step - 1e-9))
    h = model.period / n_sub
    n = max(1, math.ceil(horizon / h - 1e-9))
    k = len(aim)
    x, y = np.full(k, float(pose[0])), np.full(k, float(pose[1]))
    th = np.full(k, float(pose[2]))
    v, u = np.full(k, float(v_now)), np.full(k, float(u_now))
    v_cmd, u_cmd = v, u
    xy, speeds = np.empty((k, n + 1, 2)), np.empty((k, n + 1))
    xy[:, 0, 0], xy[:, 0, 1], speeds[:, 0] = x, y, v
    for i in range(n):
        if i % n_sub == 0:
            beta = (aim - th + np.pi) % (2.0 * np.pi) - np.pi
            v_cmd = speed_command(speed * np.maximum(np.cos(beta), 0.0), v, model)
            u_cmd = turn_command(beta, u, model)
            if model.turn_first:
                th = th + ramp_turns(u, u_cmd, model.turn_accel, model.period)
        v1 = approach(v, v_cmd, model.accel * h)
        u1 = approach(u, u_cmd, model.turn_accel * h)
        vm, half = 0.5 * (v + v1), (0.0 if model.turn_first else 0.25) * (u + u1) * h
        chord = vm * h * np.sinc(half / np.pi)
        x = x + chord * np.cos(th + half)
        y = y + chord * np.sin(th + half)
        th = th + 2.0 * half
        v, u = v1, u1
        xy[:, i + 1, 0], xy[:, i + 1, 1], speeds[:, i + 1] = x, y, v
    return np.asarray(h * np.arange(n + 1), dtype=float), xy, speeds


def stoppable(
    times: FloatArray, xy: FloatArray, speeds: FloatArray, ttc: FloatArray, model: RampModel
) -> BoolArray:
    """Per path of :func:`rollout`, whether the robot, having followed it for one period, can
    still stop before its first contact ``ttc`` [s]: the path length to the contact is at least
    ``v_T T + v_T^2 / (2 a)`` (``v_T`` its speed after the period; the braking starts at the
    next decision at the latest).  A path without contact is stoppable.

    >>> m = RampModel(1.0, 1.0, 1.0, math.inf, 0.25)
    >>> t = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    >>> xy = np.stack([np.column_stack([t, 0 * t]), np.column_stack([t, 0 * t])])
    >>> stoppable(t, xy, np.ones((2, 5)), np.array([0.5, 1.0]), m).tolist()  # 0.75 m needed
    [False, True]
    """
    step = np.hypot(*np.moveaxis(np.diff(xy, axis=1), -1, 0))
    length = np.concatenate([np.zeros((len(xy), 1)), np.cumsum(step, axis=1)], axis=1)
    finite = np.isfinite(ttc)
    at = np.where(finite, ttc, 0.0)
    to_contact = np.array([np.interp(a, times, row) for a, row in zip(at, length, strict=True)])
    v_t = speeds[:, min(int(np.searchsorted(times, model.period - 1e-9)), len(times) - 1)]
    need = v_t * model.period + v_t * v_t / (2.0 * model.accel)
    return np.asarray(~finite | (to_contact >= need), dtype=bool)


def path_risk(
    times: FloatArray,
    xy: FloatArray,
    discs: tuple[FloatArray, FloatArray, FloatArray],
    horizon: float,
    comfort: float,
    comfort_horizon: float,
    margin: float,
    spread: float = 0.0,
    min_speed: float = 0.0,
) -> tuple[FloatArray, FloatArray]:
    """``(ttc, pen)`` per path (:func:`uvnav.geometry.contact.candidate_risk`'s numbers for a
    path of straight segments): the first contact [s] within ``horizon`` of the robot, moving
    along each segment of ``xy`` (K, S + 1, 2) at constant velocity between ``times`` (S + 1,),
    with the discs (centres ``q``, velocities ``w``, radius sums ``reach``) moving at constant
    velocity, each disc's reach grown by ``spread`` [m/s] times the end time of the segment
    (where a body may be once it changes its velocity); and the largest ``comfort - gap`` over
    [0, ``comfort_horizon``] (0 when none) over the discs moving at ``min_speed`` [m/s] or faster
    (a body standing still is kept clear of, not at a comfort distance).

    >>> t = np.array([0.0, 1.0, 2.0])
    >>> xy = np.zeros((1, 3, 2))  # standing at the origin
    >>> disc = (np.array([[3.0, 0.0]]), np.array([[-1.0, 0.0]]), np.array([1.0]))
    >>> [round(float(path_risk(t, xy, disc, 4.0, 0.0, 1.0, 0.0, g)[0][0]), 6) for g in (0, 0.5)]
    [2.0, 1.0]
    """
    q, w, reach = discs
    k = xy.shape[0]
    if not len(q):
        return np.full(k, np.inf), np.zeros(k)
    t0, h = times[:-1], np.diff(times)
    seg_h = np.clip(np.minimum(h, horizon - t0), 0.0, None)
    vel = np.diff(xy, axis=1) / h[None, :, None]
    rel = q[None, None] + w[None, None] * t0[None, :, None, None] - xy[:, :-1, None, :]
    rel_vel = vel[:, :, None, :] - w[None, None]
    grown = reach[None, None, :] + spread * (t0 + h)[None, :, None]
    t = first_contact(rel, rel_vel, grown, seg_h[None, :, None], margin)
    ttc = (t0[None, :, None] + t).min(axis=(1, 2))
    near = t0 < comfort_horizon
    c_h = np.minimum(h[near], comfort_horizon - t0[near])
    gap = segment_gap(rel[:, near], rel_vel[:, near], reach[None, None, :], c_h[None, :, None])
    gap = np.where(np.hypot(w[:, 0], w[:, 1]) >= min_speed, gap, np.inf)
    pen = np.clip(comfort - gap, 0.0, None).max(axis=(1, 2)) if np.any(near) else np.zeros(k)
    return np.asarray(ttc, dtype=float), np.asarray(pen, dtype=float)


def segment_gap(
    rel_pos: FloatArray, rel_vel: FloatArray, reach: FloatArray, span: FloatArray
) -> FloatArray:
    """Smallest ``|rel_pos - rel_vel t| - reach`` over t in [0, ``span``] [m], elementwise
    (:func:`uvnav.geometry.contact.closest_gap` with a span per pair).

    >>> segment_gap(np.array([2.0, 1.0]), np.array([1.0, 0.0]), np.array(0.5), np.array(1.0))
    array(0.91421356)
    """
    a = np.einsum("...i,...i->...", rel_vel, rel_vel)
    b = np.einsum("...i,...i->...", rel_pos, rel_vel)
    t = np.clip(b / np.maximum(a, 1e-12), 0.0, span)
    gap = rel_pos - rel_vel * t[..., None]
    return np.asarray(np.hypot(gap[..., 0], gap[..., 1]) - reach, dtype=float)


def preferred_under_limits(position: FloatArray, goal: FloatArray, model: RampModel) -> FloatArray:
    """V_max toward ``goal`` [m/s], lowered to ``dist / T`` near it and to the speed from which
    the robot can still stop at it, ``sqrt(2 a dist)``."""
    pref = toward_goal(position, goal, model.v_max, model.period)
    dist = math.hypot(*(np.asarray(goal, dtype=float) - position))
    speed = math.hypot(pref[0], pref[1])
    cap = math.sqrt(2.0 * model.accel * dist)
    return pref * (cap / speed) if speed > cap else pref


def path_social(
    times: FloatArray,
    xy: FloatArray,
    discs: tuple[FloatArray, FloatArray, FloatArray],
    horizon: float,
    forecast: float,
    band: float,
) -> FloatArray:
    """The social term [m] of v2 (:mod:`uvnav.controllers.zhang2019_v2`, "Social comfort") of
    each rolled-out path ``xy`` (K, S + 1, 2) at ``times`` (S + 1,) [s]: over its segments that
    start before ``horizon`` [s], the largest ``reach + band - g`` (clipped at 0) over the moving
    discs (centres, velocities, radius sums), ``g`` the distance from the robot on the segment
    to the disc's forecast over ``forecast`` [s] (:func:`uvnav.geometry.contact.forecast_gap`)."""
    q, w, reach = discs
    near = int(np.searchsorted(times, horizon, side="left"))  # segments 0 .. near - 1
    moving = (w[:, 0] != 0.0) | (w[:, 1] != 0.0)
    if not bool(moving.any()) or near < 1:
        return np.zeros(xy.shape[0])
    q, w, reach = q[moving], w[moving], reach[moving]
    t = times[: near + 1]
    d = q[None, None] + w[None, None] * t[None, :, None, None] - xy[:, : near + 1, None, :]
    e = np.broadcast_to((w * forecast)[None, None], d[:, :-1].shape)
    g = forecast_gap(d[:, :-1], np.diff(d, axis=1), e).min(axis=1)
    return np.asarray(np.clip(reach[None, :] + band - g, 0.0, None).max(axis=1))
