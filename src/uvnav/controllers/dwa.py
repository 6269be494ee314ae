"""``dwa-v1``: the Dynamic Window Approach, a classical baseline for the thesis's Ch. 2 law.

Reference: D. Fox, W. Burgard, S. Thrun, "The dynamic window approach to collision avoidance",
*IEEE Robotics & Automation Magazine* 4(1), 1997 — §4.1 "Search space" (circular trajectories;
admissible velocities V_a, v <= sqrt(2 dist(v, w) v'_b); dynamic window V_d, the velocities
reachable within the next decision interval under the acceleration limits; resulting search space
V_r = V_s ∩ V_a ∩ V_d) and §4.2 "Optimization" (G(v, w) = sigma(alpha heading(v, w) +
beta dist(v, w) + gamma vel(v, w))).  The equation numbers of the printed paper were not
available to us; the section names above are the paper's.

What is implemented, for the thesis's unicycle (2.1)-(2.4) and sensing model (§2.2):

* **Search space.** V_s = [0, V_max] x [-U_max, U_max].  The thesis's unicycle has *no*
  acceleration limits; DWA needs some, so ``max_accel`` (1.0 m/s^2) and ``max_ang_accel``
  (4.0 rad/s^2) are chosen: the robot reaches V_max = 0.707 m/s in 0.7 s and U_max = 1.414 rad/s
  in 0.35 s, a brisk but physical small robot.  V_d is the window of half-widths
  ``max_accel * T`` and ``max_ang_accel * T`` around the current (v, w), T the decision period
  (measured between calls); a vehicle with tighter acceleration limits of its own
  (``UnicycleSpec.accel_max``, ``turn_accel_max``) narrows the window to them.  The current v is
  the observed speed, the current w the law's own last command (the observation carries no turn
  rate).  The window is sampled on a regular
  ``v_samples x u_samples`` grid (15 x 21), its corners included.
* **Rollouts.** Every sample is rolled out for ``horizon`` [s] at steps of ``rollout_dt`` [s]
  with the *exact* arc of the unicycle (the chord formula of
  :func:`uvnav.dynamics.unicycle.unicycle_advance`, here on arrays), not Euler.  Like Fox et al.
  the command is assumed to be reached at once (it is, for the simulated unicycle).
* **Obstacles.** Predicted at constant velocity over the horizon from what the observation gives
  (centre velocity v_i and angular velocity u_i, true or estimated as the simulator decides):
  a polygon's outline is rotated by u_i t about its centre and translated by v_i t, a disc's
  centre translated.  ``predict_motion=False`` freezes them (the original, static DWA; used by
  the tests to show what the prediction buys).  The clearance of a rollout point is its signed
  distance to the predicted body minus the robot radius and ``safety_margin`` — the body inflated
  by the robot's disc.  Points, time steps, edges and discs are all numpy arrays: one
  (samples x steps x edges) point-to-segment pass with a crossing-parity inside test, reduced per
  polygon with ``minimum.reduceat``; obstacles whose bounding disc cannot come within reach over
  the horizon are culled first.
* **Admissible velocities.** Fox's stopping rule v <= sqrt(2 dist(v, w) v'_b), with dist the arc
  length v t_c to the first predicted contact (infinite if none) less the arc v T run before the
  next decision, when braking can start at the earliest, and v'_b = ``brake_accel``.  A contact
  is a rollout point inside an inflated body; when the robot is already inside the margin, only
  points deeper than where it is count (else no sample could back out).
  Their angular counterpart is dropped (the unicycle's turn rate does not need braking room:
  it has no angular inertia).  Among moving obstacles the rule is a heuristic (braking does not
  help against an obstacle that comes to the robot), kept because it is the paper's; the
  clearance term then prefers the samples that avoid predicted contact.  When no sample is
  admissible the law brakes as hard as the window allows toward the sample with the latest first
  contact, then the largest clearance (mode ``"STOP"``).
* **Objective.** G = alpha heading + beta clearance + gamma velocity, each term scaled to [0, 1]
  by its natural range (Fox et al. normalise too; scaling by the spread over the window instead
  would blow differences of millimetres up to full weight): heading = 1 - |angle to T| / pi
  evaluated at the rollout pose at ``heading_time`` [s] (Fox: after the next interval; the
  default, the end of the 3 s rollout, is what lets the law get round an obstacle straight ahead:
  measured, with 1 s it stalls in front of a head-on disc),
  clearance = min(dist(v, w), ``clearance_cap``) / ``clearance_cap`` with Fox's dist, the arc
  length to the first predicted contact (a minimum
  clearance over the whole rollout instead makes the robot stop in front of an obstacle that
  stands between it and T: standing still keeps the clearance, any motion toward T loses it),
  velocity = 1 - |v - v_des| / V_max with
  v_des = min(V_max, sqrt(2 brake_accel d_T)) (Fox use v / V_max; slowing down near T lets the
  robot stop on it instead of orbiting, d_T the distance to T).  Fox's smoothing sigma over the
  window is not applied (the sampled window is small; smoothing would blur the narrow admissible
  gaps between moving obstacles).
* **Margins.** The default ``safety_margin`` (0.3 m) is large: the Ch. 2 obstacles turn at random,
  so the constant-velocity prediction is wrong within the horizon, and with 0.05-0.2 m the law
  collided on ``thesis-ch2-one-obstacle`` (measured).
* **Mode** (for the mode-switch metric): ``"M1"`` when no predicted obstacle limits the chosen
  sample's clearance term, ``"M2"`` when one does, ``"STOP"`` as above.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from uvnav.controllers.base import ControllerInfo, UnicycleController, check_params, register
from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.geometry.angles import FloatArray
from uvnav.sensors.observation import Observation, ObstacleReading

_EPS = float(np.finfo(float).eps)

#: most samples of either window (``v_samples``, ``u_samples``): 100 x 100 samples cost about
#: 13 ms a decision over a 15-step rollout
MAX_WINDOW_SAMPLES = 100


@dataclass(frozen=True)
class DwaParams:
    """Parameters of ``dwa-v1``.

    Attributes:
        v_samples: samples of the speed window (2 .. :data:`MAX_WINDOW_SAMPLES`).
        u_samples: samples of the turn-rate window (2 .. :data:`MAX_WINDOW_SAMPLES`).
        horizon: rollout horizon [s].
        rollout_dt: time between rollout points [s] (<= horizon).
        max_accel: speed change reachable per second [m/s^2] (the window's half-width / T).
        max_ang_accel: turn-rate change reachable per second [rad/s^2].
        brake_accel: braking deceleration v'_b of the admissibility rule [m/s^2].
        heading_weight: alpha, weight of the heading term.
        clearance_weight: beta, weight of the clearance term.
        velocity_weight: gamma, weight of the velocity term.
        heading_time: time along the rollout at which the heading term is evaluated [s]
            (clamped to the horizon).
        clearance_cap: clearance [m] beyond which the clearance term is saturated.
        safety_margin: clearance [m] kept beyond the robot's radius.
        predict_motion: predict obstacles along their observed velocities (False: static DWA).
    """

    v_samples: int = 15
    u_samples: int = 21
    horizon: float = 3.0
    rollout_dt: float = 0.2
    max_accel: float = 1.0
    max_ang_accel: float = 4.0
    brake_accel: float = 1.0
    heading_weight: float = 1.0
    clearance_weight: float = 1.0
    velocity_weight: float = 0.3
    heading_time: float = 3.0
    clearance_cap: float = 1.0
    safety_margin: float = 0.3
    predict_motion: bool = True

    def __post_init__(self) -> None:
        for name in ("v_samples", "u_samples"):
            value = getattr(self, name)
            if (
                not isinstance(value, int)
                or isinstance(value, bool)
                or not 2 <= value <= MAX_WINDOW_SAMPLES
            ):
                raise ValueError(
                    f"{name} must be an integer from 2 to {MAX_WINDOW_SAMPLES} (got {value!r})"
                )
        check_params(
            self,
            positive=(
                "horizon",
                "rollout_dt",
                "max_accel",
                "max_ang_accel",
                "brake_accel",
                "clearance_cap",
            ),
            non_negative=(
                "heading_weight",
                "clearance_weight",
                "velocity_weight",
                "heading_time",
                "safety_margin",
            ),
        )
        if self.rollout_dt > self.horizon:
            raise ValueError(
                f"rollout_dt must be <= horizon (got {self.rollout_dt} > {self.horizon})"
            )
        if self.horizon / self.rollout_dt > 200:
            raise ValueError("horizon / rollout_dt must be <= 200 rollout steps")
        if not isinstance(self.predict_motion, bool):
            raise ValueError(f"predict_motion must be a bool (got {self.predict_motion!r})")


def rollout_times(horizon: float, step: float) -> FloatArray:
    """Rollout times ``step, 2 step, ..., horizon`` [s] (the last one clamped to ``horizon``)."""
    n = max(1, math.ceil(horizon / step - 1e-9))
    return np.minimum(np.arange(1, n + 1) * step, horizon)


def rollout_poses(
    pose: FloatArray, v: FloatArray, u: FloatArray, times: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Exact unicycle arcs from ``pose`` under constant commands, evaluated at ``times``.

    Args:
        pose: ``[x, y, theta]`` ([m], [m], [rad]).
        v: speeds [m/s], shape (S,).
        u: turn rates [rad/s], shape (S,).
        times: times [s] after now, shape (K,).

    Returns:
        ``x``, ``y``, ``theta`` of shape (S, K) (theta not wrapped), the same chord formula as
        :func:`uvnav.dynamics.unicycle.unicycle_advance`.
    """
    half = 0.5 * u[:, None] * times[None, :]
    chord = v[:, None] * times[None, :] * np.sinc(half / math.pi)
    ang = pose[2] + half
    return pose[0] + chord * np.cos(ang), pose[1] + chord * np.sin(ang), pose[2] + 2.0 * half


def predicted_clearance(
    px: FloatArray,
    py: FloatArray,
    times: FloatArray,
    readings: Sequence[ObstacleReading],
    *,
    inflate: float,
    predict_motion: bool = True,
    cutoff: float = np.inf,
) -> FloatArray:
    """Signed gap [m] between rollout points and the predicted obstacle bodies inflated by
    ``inflate`` [m] (negative: contact), minimised over the obstacles.

    Args:
        px, py: rollout points [m], shape (S, K), column k at ``times[k]``.
        times: times [s] of the columns, shape (K,).
        readings: the obstacles; polygons are rotated by u_i t about their centre and translated
            by v_i t, discs translated (or frozen with ``predict_motion=False``).
        inflate: robot radius plus margin [m].
        cutoff: clearances above this [m] may be returned as a lower bound (>= ``cutoff``):
            a polygon's exact distance is computed only at the points within ``cutoff +
            inflate`` of its predicted bounding disc.

    Returns:
        Clearance of shape (S, K); ``inf`` where there are no obstacles.
    """
    s, k = px.shape
    # flat layout: one long axis of (sample, time) pairs, obstacles on the short outer axis, so
    # that numpy's inner loops run over the long axis
    pxf, pyf = px.ravel(), py.ravel()
    kl = np.tile(np.arange(k), s)  # time index of each flat point
    best = np.full(s * k, np.inf)
    t = times if predict_motion else np.zeros_like(times)
    discs = [r for r in readings if r.is_disc or len(r.outline) < 2]
    polys = [r for r in readings if not (r.is_disc or len(r.outline) < 2)]
    if discs:
        centre = np.array([r.centre for r in discs], dtype=float)  # (J, 2)
        vel = np.array([r.velocity for r in discs], dtype=float)
        radius = np.array([max(r.radius, 0.0) for r in discs], dtype=float)
        cx = centre[:, 0][:, None] + vel[:, 0][:, None] * t[None, :]  # (J, K)
        cy = centre[:, 1][:, None] + vel[:, 1][:, None] * t[None, :]
        gap = np.hypot(pxf[None, :] - cx[:, kl], pyf[None, :] - cy[:, kl]) - radius[:, None]
        best = np.minimum(best, gap.min(axis=0))
    if polys:
        best = np.minimum(best, _polygon_gaps(pxf, pyf, kl, t, polys, cutoff))
    out: FloatArray = (best - inflate).reshape(s, k)
    return out


def _polygon_gaps(
    px: FloatArray,
    py: FloatArray,
    kl: np.ndarray,
    t: FloatArray,
    polys: Sequence[ObstacleReading],
    cutoff: float,
) -> FloatArray:
    """Signed distance [m] of flat rollout points ``(px, py)`` (time index ``kl`` into ``t``) to
    the predicted polygons, minimised over the polygons: shape (L,).  Exact where the
    bounding-disc distance is below ``cutoff``, the bounding-disc distance (a lower bound of the
    exact one) elsewhere.

    The polygons are padded to a common vertex count (the padding repeats the first vertex:
    zero-length edges that change neither the distance nor the crossing parity), the
    (point, polygon) pairs that need the exact value are gathered with one ``nonzero``, and each
    is tested against all its polygon's edges at once: distance to the nearest edge and crossing
    parity of the ray along +x (inside test).
    """
    n_poly = len(polys)
    n_max = max(len(r.outline) for r in polys)
    local = np.empty((n_max + 1, n_poly, 2))
    for j, r in enumerate(polys):
        outline = np.asarray(r.outline, dtype=float)
        local[: len(outline), j] = outline
        local[len(outline) :, j] = outline[0]
    centre = np.array([r.centre for r in polys], dtype=float)  # (P, 2)
    vel = np.array([r.velocity for r in polys], dtype=float)
    omega = np.array([r.angular_velocity for r in polys], dtype=float)
    bound = np.array([max(r.bounding_radius, 0.0) for r in polys], dtype=float)
    rel = local - centre[None, :, :]  # (M+1, P, 2)
    cx = centre[:, 0][None, :] + vel[:, 0][None, :] * t[:, None]  # (K, P)
    cy = centre[:, 1][None, :] + vel[:, 1][None, :] * t[:, None]
    ang = omega[None, :] * t[:, None]
    c, sn = np.cos(ang)[None], np.sin(ang)[None]  # (1, K, P)
    vx = cx[None] + c * rel[:, None, :, 0] - sn * rel[:, None, :, 1]  # (M+1, K, P)
    vy = cy[None] + sn * rel[:, None, :, 0] + c * rel[:, None, :, 1]
    # bounding-disc distance of every (polygon, point): (P, L)
    cxl, cyl = cx.T[:, kl], cy.T[:, kl]
    gap = np.hypot(px[None, :] - cxl, py[None, :] - cyl) - bound[:, None]
    pi, li = np.nonzero(gap < cutoff)
    if len(li):
        ki = kl[li]
        qx, qy = px[li][None, :], py[li][None, :]  # (1, N)
        ax, ay = vx[:-1, ki, pi], vy[:-1, ki, pi]  # (M, N)
        ex, ey = vx[1:, ki, pi] - ax, vy[1:, ki, pi] - ay
        len2 = ex * ex + ey * ey
        dx, dy = qx - ax, qy - ay
        lam = np.clip((dx * ex + dy * ey) / np.where(len2 > 1e-24, len2, 1.0), 0.0, 1.0)
        dist = np.sqrt(((dx - lam * ex) ** 2 + (dy - lam * ey) ** 2).min(axis=0))
        straddle = (ay > qy) != (ay + ey > qy)
        x_cross = ax + dy * ex / np.where(ey == 0.0, 1.0, ey)
        inside = np.count_nonzero(straddle & (qx < x_cross), axis=0) % 2 == 1
        gap[pi, li] = np.where(inside, -dist, dist)
    out: FloatArray = gap.min(axis=0)
    return out


class DwaController(UnicycleController):
    """Dynamic Window Approach (Fox, Burgard & Thrun 1997), see the module docstring."""

    name: ClassVar[str] = "dwa-v1"

    def __init__(self, params: DwaParams | None = None) -> None:
        super().__init__()
        self.params = params or DwaParams()
        self._last_u = 0.0
        self._times = rollout_times(self.params.horizon, self.params.rollout_dt)
        #: the last decision's samples and scores (for inspection and tests)
        self.last_samples: tuple[FloatArray, FloatArray] | None = None

    def _reset_law(self, rng: np.random.Generator) -> None:
        self._last_u = 0.0
        self.last_samples = None

    def window(self, speed: float, period: float) -> tuple[FloatArray, FloatArray]:
        """The sampled dynamic window V_s ∩ V_d: speeds [m/s] and turn rates [rad/s], flattened
        to shape (v_samples * u_samples,)."""
        p, spec = self.params, self._spec
        v_now = min(max(speed if math.isfinite(speed) else 0.0, 0.0), spec.v_max)
        u_now = min(max(self._last_u, -spec.u_max), spec.u_max)
        # the vehicle's own acceleration limits where it has tighter ones than the law's
        accel = min(p.max_accel, getattr(spec, "accel_max", math.inf))
        ang_accel = min(p.max_ang_accel, getattr(spec, "turn_accel_max", math.inf))
        dv, du = accel * period, ang_accel * period
        v_lo, v_hi = max(0.0, v_now - dv), min(spec.v_max, v_now + dv)
        u_lo, u_hi = max(-spec.u_max, u_now - du), min(spec.u_max, u_now + du)
        vv, uu = np.meshgrid(
            np.linspace(v_lo, v_hi, p.v_samples),
            np.linspace(u_lo, u_hi, p.u_samples),
            indexing="ij",
        )
        return vv.ravel(), uu.ravel()

    def act(self, obs: Observation) -> UnicycleCommand:
        p, spec = self.params, self._spec
        period = min(self.decision_period(obs.time), 1.0)
        pose = np.asarray(obs.pose, dtype=float)
        v, u = self.window(float(obs.speed), period)
        times = self._times
        xs, ys, ths = rollout_poses(pose, v, u, times)

        inflate = spec.radius + p.safety_margin
        reach = (spec.v_max * times[-1]) + inflate + p.clearance_cap
        relevant = [
            r
            for r in obs.obstacles
            if float(np.hypot(*(r.centre - pose[:2])))
            - max(r.bounding_radius, r.radius)
            - (r.speed * times[-1] if p.predict_motion else 0.0)
            <= reach
        ]
        if relevant:
            clear = predicted_clearance(
                xs,
                ys,
                times,
                relevant,
                inflate=inflate,
                predict_motion=p.predict_motion,
                cutoff=p.clearance_cap + inflate,
            )
        else:
            clear = np.full(xs.shape, np.inf)
        clear = np.where(np.isnan(clear), -np.inf, clear)
        # contact: the inflated bodies are entered; from inside the margin, only going deeper
        # counts (so that the robot may back out of a margin it has been pushed into)
        now = min((r.distance for r in obs.obstacles), default=math.inf) - inflate
        hit = clear < min(0.0, now - 1e-9)
        any_hit: np.ndarray = np.asarray(hit.any(axis=1))
        # the contact lies between the last free rollout point and the first hit: take the
        # former (conservative by at most one rollout step)
        free_until = np.concatenate([[0.0], times])[np.argmax(hit, axis=1)]
        t_contact = np.where(any_hit, free_until, np.inf)
        min_clear = clear.min(axis=1)
        # Fox's admissibility v <= sqrt(2 dist v'_b), dist = v t_c the arc length to contact,
        # with braking starting at the next decision: v <= sqrt(2 v'_b (v t_c - v T))
        arc = np.where(any_hit, v * np.where(any_hit, t_contact, 0.0), np.inf)
        room = np.maximum(arc - v * period, 0.0)
        admissible = v <= np.sqrt(2.0 * p.brake_accel * room) + 1e-12
        goal = self._goal
        heading = heading_term(xs, ys, ths, times, goal, p.heading_time, v * p.rollout_dt)
        # Fox's dist(v, w): arc length to the first predicted contact (the cap when none)
        clearance = np.minimum(np.where(np.isfinite(arc), arc, p.clearance_cap), p.clearance_cap)
        clearance = clearance / p.clearance_cap
        d_goal = float(np.hypot(goal[0] - pose[0], goal[1] - pose[1]))
        v_des = min(spec.v_max, math.sqrt(2.0 * p.brake_accel * d_goal))
        velocity = 1.0 - np.abs(v - v_des) / spec.v_max
        score = p.heading_weight * heading + p.clearance_weight * clearance
        score = score + p.velocity_weight * velocity
        if admissible.any():
            best = int(np.argmax(np.where(admissible, score, -np.inf)))
            self._mode = "M2" if bool(any_hit[best]) else "M1"
        else:  # no admissible sample: brake, keeping away from the earliest contact
            key = np.lexsort((-v, min_clear, t_contact))  # last = latest contact, then clearance
            best = int(key[-1])
            self._mode = "STOP"
        cmd_v = float(np.clip(v[best], 0.0, spec.v_max))
        cmd_u = float(np.clip(u[best], -spec.u_max, spec.u_max))
        if not (math.isfinite(cmd_v) and math.isfinite(cmd_u)):
            cmd_v, cmd_u = 0.0, 0.0
        self._last_u = cmd_u
        self.last_samples = (v, u)
        return UnicycleCommand(cmd_v, cmd_u)


def heading_term(
    xs: FloatArray,
    ys: FloatArray,
    ths: FloatArray,
    times: FloatArray,
    goal: FloatArray,
    heading_time: float,
    step: FloatArray,
) -> FloatArray:
    """Fox's heading term, 1 - |angle to T| / pi, per sample (rows of the rollout poses
    ``xs``, ``ys``, ``ths`` at ``times``) [0, 1].

    Evaluated at ``heading_time`` — or, where the rollout passes T before then, at its point
    nearest T, and 1 (less 0.01 d / ``step``, so that the nearest pass wins) where that point
    is within the sample's rollout ``step`` [m] of T (it reaches T).  Evaluated past T, a
    rollout that drives onto T would face away from it and score worst, so that standing still
    short of T would score best and the robot would park short of T (0.13 m from it, measured).

    >>> t = np.array([1.0, 2.0, 3.0])
    >>> xs = np.array([[0.5, 1.0, 1.5], [0.0, 0.0, 0.0]]); z = np.zeros_like(xs)
    >>> heading_term(xs, z, z, t, np.array([1.0, 0.0]), 3.0, np.array([0.5, 0.0])).tolist()
    [1.0, 1.0]
    >>> h = heading_term(xs, z + 0.1, z, t, np.array([1.0, 0.0]), 3.0, np.array([0.5, 0.5]))
    >>> h.round(3).tolist()  # a pass 0.1 m off T; a robot at rest 0.1 rad off its bearing
    [0.998, 0.968]
    """
    k_h = int(np.clip(np.searchsorted(times, heading_time - 1e-9), 0, len(times) - 1))
    d = np.hypot(goal[0] - xs[:, : k_h + 1], goal[1] - ys[:, : k_h + 1])
    k = np.argmin(d, axis=1)
    rows = np.arange(len(xs))
    gx, gy = goal[0] - xs[rows, k], goal[1] - ys[rows, k]
    err = np.angle(np.exp(1j * (np.arctan2(gy, gx) - ths[rows, k])))
    heading = 1.0 - np.abs(err) / math.pi
    reach = np.maximum(step, 1e-9)
    passing = 1.0 - 0.01 * d[rows, k] / reach  # the nearest pass first
    return np.asarray(np.where(d[rows, k] <= reach, passing, heading), dtype=float)


register(
    ControllerInfo(
        name="dwa-v1",
        factory=DwaController,
        params_type=DwaParams,
        summary="Dynamic Window Approach: sampled (v, w) window, exact-arc rollouts against "
        "constant-velocity obstacle predictions, G = alpha heading + beta clearance + gamma vel.",
        reference="D. Fox, W. Burgard, S. Thrun, IEEE Robot. Autom. Mag. 4(1), 1997",
        acceleration_limits=True,
    )
)
