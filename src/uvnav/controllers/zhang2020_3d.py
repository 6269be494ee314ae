"""``zhang2020-3d-v1``: the thesis's sliding-mode law for a flying robot among moving, rotating,
non-convex 3D obstacles, with AR prediction of their motion.

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 3, §3.3, eqs. (3.11)-(3.22), Figs. 3.2-3.5 (originally "Collision-free
Navigation of Flying Robots in Outdoor Environments with Dynamic Obstacles", ICCAR 2020).

* **M1** (3.11)-(3.12): V_R = V_max straight to E (turning toward E at the bounded rate when not
  facing it).
* **M2**, four steps at each decision time t0:

  1. *predict* v_i, u_i of the obstacle (AR models (3.13)-(3.14) sampled every T_s = 1 s, see
     :mod:`uvnav.prediction.autoregressive`; with ``oracle=True`` the true current rates);
  2. *direction*: the on-line frame (origin c_R, Y' toward E, X' horizontal, see
     :func:`uvnav.geometry.frames3d.online_frame`); alpha(t0), the angle of L_center (robot ->
     mass centre) from Y', counter-clockwise; tag '+' for alpha in [0, pi/2), '-' otherwise (3.15);
  3. *avoiding point*: the obstacle, projected into the on-line plane, seen from the robot; the
     enlarged vision cone (half-angle alpha0 beyond the obstacle's silhouette) gives r*_min on the
     tagged side (3.16)-(3.17);
  4. *motion*: the forecast sphere (3.17) of radius ||v_i*|| T_s around r*_min, its tangents from
     the robot at angles alpha^1, alpha^2 (3.18)-(3.20), J, f and (3.21)-(3.22) in the on-line
     frame; the result is mapped back to (V_R, u_R) in 3D with (a_R, u_R) = 0.

Where the thesis is ambiguous this implementation chooses as follows (docs/thesis-notes.md):

1. *On-line plane.* X' = Y' x z / ||Y' x z|| (horizontal, to the right of Y'); when E is straight
   above or below the robot the previous X' is kept.  The obstacle is projected onto the plane
   along Z' (all its vertices, at every height): the robot passes it within the plane, so the
   in-plane clearance is a lower bound of the 3D clearance — conservative and collision-free by
   construction for a robot that stays in the plane.
2. *Sign of alpha and meaning of '+'.* alpha is measured counter-clockwise from Y' (seen from +Z');
   '+' (alpha >= 0, the centre on the -X' side) passes on the +X' side — the shorter way round,
   the reading that makes the tag useful.  The tag is fixed when avoidance of an obstacle starts.
3. *Forecast sphere radius.* ||v_i*|| T_s as in (3.17), plus the robot's radius and
   ``safety_margin`` (a zero radius would steer the robot onto the surface of a static obstacle);
   the horizon is shortened near the body (the motion term is at most half the free distance) so
   that the robot never sits inside the spheres, where no tangent exists.  The predicted rotation
   u_i* enters through the boundary points rotated by u_i* T_s about the mass centre, taken
   together with the current ones.
4. *Which circles (non-convex bodies).* The tangent on the tagged side is taken over the forecast
   circles of *all* projected boundary points (the silhouette), rotated out by alpha0: for a convex
   body this is the tangent to the circle at r*_min, for a non-convex one it never grazes a spike
   beyond r*_min.  Other obstacles within D whose inflated silhouettes contain that direction push
   it further out on the same side (the robot avoids the nearest obstacle "and its neighbours");
   neighbours count up to 2 D.  *A group is passed on one side*: when the nearest blocking
   obstacle changes during M2 the new one takes the previous one's passing side (even if it had
   one from before), and a new target with no side takes that of the nearest obstacle within 2 D
   that has one; only a target with no tagged neighbour gets its side from the alpha rule (3.15).
   Two bodies tagged by their own alphas with opposite sides steer the robot into the gap between
   them, which moving bodies close (the cause of every collision of the 500-scene campaign
   before this rule).
5. *J.* The thesis compares |l^1| and |l^2|, which are equal (both are ||v*|| / tan gamma); the
   tangent on the tagged side is used, which is what the tag is for.
6. *f and the sign of u.* u_R* = -U_max f would turn the robot away from l_J with beta measured
   from its velocity to l_J; the robot is turned *toward* l_J at the rate U_max, with a boundary
   layer (the rate that closes the angle in one decision period) against chattering.
7. *Speed.* (3.21) V_R* = ||l_J|| (tangent length per T_s) with ``speed_law="tangent"``, floored
   at 1.5 ||v_i*|| ((3.9) needs the robot faster than the obstacle) and capped at V_max; the
   default ``"max"`` keeps V_max, scaled by cos(beta) while turning (never below the floor, nor
   below V_max / 2) as the Chapter 2 law does.
8. *Switching distance D, written twice.* The second sentence of §3.3 repeats "shorter than D" for
   leaving M2; it is read as "longer than D".  M2 is entered when an obstacle is within D and in
   the robot's way (its inflated silhouette contains the direction to E or the robot's velocity
   relative to the obstacle) and left when none is.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar, Literal, NamedTuple, cast

import numpy as np

from uvnav.controllers.base import ControllerInfo, check_params, register
from uvnav.controllers.base3d import Vehicle3DController
from uvnav.dynamics.vehicle3d import Vehicle3DCommand
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.frames3d import OnlineFrame, online_frame, rotation_from_vector
from uvnav.geometry.kernels3d import numba_enabled, plane_shadow
from uvnav.prediction.autoregressive import ARPredictor
from uvnav.sensors.sensing3d import Observation3D, ObstacleReading3D


@dataclass(frozen=True)
class Zhang2020Params:
    """Parameters of ``zhang2020-3d-v1``.

    Attributes:
        alpha0: enlargement angle alpha0 of the vision cone [rad].
        switch_distance: D, the obstacle distance that switches M1 -> M2 [m].
        safety_margin: added to the robot radius in the forecast sphere [m].
        sample_period: T_s, the AR sampling period and forecast horizon [s].
        prediction: ``"ar"`` (AR models of the sensed rates, constant-velocity fallback) or
            ``"last"`` (the sensed rates as they are: the truth for an oracle).
        ar_max_lag: largest AR order tried.
        ar_ic: order criterion (``"bic"``, ``"aic"``, ``"hqic"``).
        speed_law: ``"max"`` or ``"tangent"`` (see the module docstring, item 7).
    """

    alpha0: float = 0.15
    switch_distance: float = 2.5
    safety_margin: float = 0.25
    sample_period: float = 1.0
    prediction: Literal["ar", "last"] = "ar"
    ar_max_lag: int = 3
    ar_ic: Literal["aic", "bic", "hqic"] = "bic"
    speed_law: Literal["max", "tangent"] = "max"

    def __post_init__(self) -> None:
        check_params(
            self, positive=("switch_distance", "sample_period"),
            non_negative=("alpha0", "safety_margin"),
        )  # fmt: skip
        if self.prediction not in ("ar", "last"):
            raise ValueError(f"prediction must be 'ar' or 'last' (got {self.prediction!r})")
        if self.speed_law not in ("max", "tangent"):
            raise ValueError(f"speed_law must be 'max' or 'tangent' (got {self.speed_law!r})")
        if not (isinstance(self.ar_max_lag, int) and 1 <= self.ar_max_lag <= 10):
            raise ValueError(f"ar_max_lag must be an integer in 1..10 (got {self.ar_max_lag!r})")


class Shadow(NamedTuple):
    """An obstacle seen in the on-line plane: angles psi measured counter-clockwise from Y' [rad].

    A named tuple (not a frozen dataclass: several are built at every decision, and a tuple is the
    cheapest immutable record in Python).

    Attributes:
        centre_angle: psi of the mass centre.
        lo, hi: the inflated silhouette's extent, as ``centre_angle + [lo, hi]`` (lo <= hi).
        inside: the robot is within the forecast radius of a boundary point.
    """

    centre_angle: float
    lo: float
    hi: float
    inside: bool

    def contains(self, psi: float, pad: float = 0.0) -> bool:
        d = wrap_scalar(psi - self.centre_angle)
        return self.lo - pad <= d <= self.hi + pad


def _norm(x: FloatArray) -> float:
    """Euclidean norm of a small vector.

    ``math.hypot`` on the list of its components: on a 3-vector every numpy call (``x @ x``,
    ``np.linalg.norm``) costs microseconds of fixed overhead, ten times the arithmetic.
    """
    return math.hypot(*x.tolist())


def _psi(xy: FloatArray) -> FloatArray:
    """Angle counter-clockwise from +Y' of plane vectors (..., 2)."""
    return np.asarray(np.arctan2(-xy[..., 0], xy[..., 1]))


def shadow_of(frame: OnlineFrame, points: FloatArray, centre: FloatArray, radius: float) -> Shadow:
    """Angular extent of ``points`` (world, (n, 3)) in the on-line plane, each inflated by a
    forecast circle of ``radius`` [m] (half-angle asin(radius / distance))."""
    q = frame.to_plane(points)
    c = frame.to_plane(centre)
    psi_c = float(_psi(c)) if float(np.hypot(*c)) > 1e-9 else float(_psi(q.mean(axis=0)))
    dist = np.hypot(q[:, 0], q[:, 1])
    rel = np.asarray(np.arctan2(np.sin(_psi(q) - psi_c), np.cos(_psi(q) - psi_c)))
    inside = bool(np.any(dist <= radius))
    ratio = np.clip(radius / np.maximum(dist, 1e-12), 0.0, 1.0)
    half = np.arcsin(ratio)
    # a point within its forecast circle: the limiting (perpendicular) direction, tilted outward
    # by the penetration depth
    pen = np.where(dist < radius, (radius - dist) / max(radius, 1e-9), 0.0)
    half = half + pen * 0.5 * math.pi
    return Shadow(psi_c, float((rel - half).min()), float((rel + half).max()), inside)


class Zhang2020Law(Vehicle3DController):
    """The thesis's Chapter 3 law (see the module docstring)."""

    name: ClassVar[str] = "zhang2020-3d-v1"

    def __init__(self, params: Zhang2020Params | None = None) -> None:
        super().__init__()
        self.p = params or Zhang2020Params()
        self._tag: dict[int, int] = {}
        self._target: int | None = None
        self._x_prev: FloatArray | None = None
        self._pred_v: dict[int, ARPredictor] = {}
        self._pred_u: dict[int, ARPredictor] = {}
        #: per obstacle: the time [s] from which its predictors keep the next sample
        self._next_sample: dict[int, float] = {}
        #: per obstacle: (u bytes, T_s) -> exp([u]x T_s) (see :meth:`_ahead`)
        self._ahead_rot: dict[int, tuple[tuple[bytes, float], FloatArray]] = {}
        #: last predictions used, by obstacle id: (v*, u*, model name) — read by probes/figures
        self.predictions: dict[int, tuple[FloatArray, FloatArray, str]] = {}

    def _reset_law(self, rng: np.random.Generator) -> None:
        self._tag = {}
        self._target = None
        self._x_prev = None
        self._pred_v = {}
        self._pred_u = {}
        self._next_sample = {}
        self._ahead_rot = {}
        self.predictions = {}

    # ----------------------------------------------------------------------------- prediction
    def _predictor(self, store: dict[int, ARPredictor], i: int) -> ARPredictor:
        if i not in store:
            store[i] = ARPredictor(
                dim=3, period=self.p.sample_period, max_lag=self.p.ar_max_lag, ic=self.p.ar_ic,
                min_samples=max(12, self.p.ar_max_lag + 3), window=40, refit_every=1,
                reselect_every=10,
            )  # fmt: skip
        return store[i]

    def observe(self, obs: Observation3D) -> None:
        """Feed the sensed rates to the per-obstacle AR models (kept once per T_s)."""
        if self.p.prediction != "ar" or self.oracle:
            return
        due = self._next_sample
        for rd in obs.obstacles:
            i = rd.obstacle_id
            if obs.time < due.get(i, -math.inf):  # between samples: nothing to offer
                continue
            self._predictor(self._pred_v, i).observe(obs.time, rd.velocity)
            self._predictor(self._pred_u, i).observe(obs.time, rd.rotation_rate)
            due[i] = self._pred_v[i].next_sample_time

    def predict(self, rd: ObstacleReading3D) -> tuple[FloatArray, FloatArray]:
        """Predicted (v_i*, u_i*) for the next sampling period (step 1)."""
        if self.p.prediction == "ar" and not self.oracle and rd.obstacle_id in self._pred_v:
            pv = self._pred_v[rd.obstacle_id].predict(1)
            pu = self._pred_u[rd.obstacle_id].predict(1)
            v, u, model = pv.mean[0], pu.mean[0], pv.model
        else:
            v, u, model = rd.velocity, rd.rotation_rate, "last"
        self.predictions[rd.obstacle_id] = (v, u, model)
        return v, u

    # ------------------------------------------------------------------------------- geometry
    def forecast_radius(self, rd: ObstacleReading3D, v: FloatArray) -> float:
        """Radius [m] of the forecast sphere (3.17): ||v_i*|| T_s plus the robot's radius and the
        margin, with the horizon shortened near the body so that the robot stays outside the
        spheres (item 3 of the module docstring)."""
        base = self._spec.radius + self.p.safety_margin
        move = _norm(v) * self.p.sample_period
        room = max(rd.distance - base, 0.0)
        return base + min(move, 0.5 * room)

    def _ahead(self, u: FloatArray, rd: ObstacleReading3D) -> FloatArray | None:
        """The predicted rotation over one period, or None when it moves no boundary point by
        more than 1 mm."""
        ts = self.p.sample_period
        if _norm(u) * ts * rd.bounding_radius > 1e-3:
            key = (u.tobytes(), ts)
            cached = self._ahead_rot.get(rd.obstacle_id)
            if cached is None or cached[0] != key:  # rates (or predictions) are held a while
                cached = self._ahead_rot[rd.obstacle_id] = (key, rotation_from_vector(u * ts))
            return cached[1]
        return None

    def _points(self, rd: ObstacleReading3D, u: FloatArray) -> FloatArray:
        """Boundary points now and rotated as predicted one period ahead (the translation is
        covered by the forecast sphere)."""
        rot = self._ahead(u, rd)
        if rot is not None:
            ahead = (rd.outline - rd.centre) @ rot.T + rd.centre
            return np.concatenate([rd.outline, ahead])
        return rd.outline

    def shadow(
        self, frame: OnlineFrame, rd: ObstacleReading3D, u: FloatArray, rho: float
    ) -> Shadow:
        """The inflated shadow of one obstacle: the compiled one-pass kernel
        (:func:`uvnav.geometry.kernels3d.plane_shadow`) when numba is installed, else
        :func:`shadow_of` on :meth:`_points` (the same values to rounding)."""
        if numba_enabled():
            psi_c, lo, hi, inside = plane_shadow(
                rd.outline, rd.centre, self._ahead(u, rd), frame.origin, frame.x_axis,
                frame.y_axis, rho,
            )  # fmt: skip
            return Shadow(psi_c, lo, hi, inside)
        return shadow_of(frame, self._points(rd, u), rd.centre, rho)

    def shadows(
        self, frame: OnlineFrame, obs: Observation3D
    ) -> dict[int, tuple[Shadow, ObstacleReading3D, FloatArray, FloatArray]]:
        """Inflated shadows of the obstacles within D (using the sensed rates)."""
        out = {}
        for rd in obs.obstacles:
            if rd.distance > 2.0 * self.p.switch_distance:  # neighbours count up to 2 D
                continue
            v, u = rd.velocity, rd.rotation_rate
            if rd.obstacle_id == self._target:
                v, u = self.predict(rd)
            rho = self.forecast_radius(rd, v)
            out[rd.obstacle_id] = (self.shadow(frame, rd, u, rho), rd, v, u)
        return out

    def in_the_way(
        self, frame: OnlineFrame, sh: Shadow, v: FloatArray, obs: Observation3D, pad: float
    ) -> bool:
        """The direction to E, or the robot's velocity relative to the obstacle, lies in the
        obstacle's inflated shadow (widened by ``pad`` [rad])."""
        if sh.inside:
            return True
        if sh.contains(0.0, pad):
            return True
        # scalar arithmetic on the components (3-vectors: numpy's per-call overhead dominates)
        x0, x1, x2 = frame.x_axis.tolist()
        y0, y1, y2 = frame.y_axis.tolist()
        v0, v1, v2 = v.tolist()
        vm = self._spec.v_max
        w0, w1, w2 = vm * y0 - v0, vm * y1 - v1, vm * y2 - v2  # V_max toward E, relative
        r1, r2 = w0 * x0 + w1 * x1 + w2 * x2, w0 * y0 + w1 * y1 + w2 * y2
        if math.hypot(r1, r2) > 1e-9 and sh.contains(math.atan2(-r1, r2), pad):
            return True
        s = max(obs.speed, 1e-3)
        h0, h1, h2 = obs.heading.tolist()
        w0, w1, w2 = h0 * s - v0, h1 * s - v1, h2 * s - v2  # the robot's velocity, relative
        r1, r2 = w0 * x0 + w1 * x1 + w2 * x2, w0 * y0 + w1 * y1 + w2 * y2
        return math.hypot(r1, r2) > 1e-9 and sh.contains(math.atan2(-r1, r2), pad)

    # ------------------------------------------------------------------------------------ act
    def act(self, obs: Observation3D) -> Vehicle3DCommand:
        period = self.decision_period(obs.time)
        self.predictions = {}  # only this decision's predictions are visible to probes
        self.observe(obs)
        frame = online_frame(obs.position, self._goal, self._x_prev)
        self._x_prev = frame.x_axis
        shadows = self.shadows(frame, obs)
        pad = self.p.alpha0 if self._mode == "M2" else 0.0
        blocking = [
            (rd.distance, i)
            for i, (sh, rd, v, _) in shadows.items()
            if rd.distance <= self.p.switch_distance
            and self.in_the_way(frame, sh, v, obs, pad if i == self._target else 0.0)
        ]
        if not blocking:
            self._mode = "M1"
            self._target = None
            return self.approach(obs, period)
        _, target = min(blocking)
        previous = self._target
        if target != self._target:
            self._target = target
            shadows = self.shadows(frame, obs)  # the target's rates are now the predicted ones
        self._mode = "M2"
        sh, rd, v, _u = shadows[target]
        if previous is not None and previous != target and previous in self._tag:
            # handing over from one obstacle to the next during M2: the new one takes the
            # passing side, even if it had one from before, so the robot goes round the group
            # instead of turning back between bodies (two sides would steer it into the gap)
            self._tag[target] = self._tag[previous]
        elif target not in self._tag:
            tagged = [(shadows[i][1].distance, i) for i in self._tag if i in shadows]
            if tagged:
                # a neighbour (within 2 D) is still being passed on a side: take that side, for
                # the same reason — the group is passed on one side
                self._tag[target] = self._tag[min(tagged)[1]]
            else:
                # (3.15): alpha = angle of L_center from Y', counter-clockwise
                self._tag[target] = 1 if sh.centre_angle >= 0.0 else -1
        tag = self._tag[target]
        for other in list(self._tag):
            if other not in shadows:
                del self._tag[other]
        psi = self.passing_angle(sh, shadows, tag)
        sin_psi, cos_psi = math.sin(psi), math.cos(psi)
        x0, x1, x2 = frame.x_axis.tolist()
        y0, y1, y2 = frame.y_axis.tolist()
        # l_J in the world: -sin(psi) X' + cos(psi) Y' (in the on-line plane)
        direction = np.array([cos_psi * y0 - sin_psi * x0, cos_psi * y1 - sin_psi * x1,
                              cos_psi * y2 - sin_psi * x2])  # fmt: skip
        speed = self.speed(obs, rd, v, direction, sh)
        return self.steer(obs, direction, speed, period)

    def passing_angle(
        self,
        sh: Shadow,
        shadows: dict[int, tuple[Shadow, ObstacleReading3D, FloatArray, FloatArray]],
        tag: int,
    ) -> float:
        """psi of l_J: the tangent on the tagged side rotated out by alpha0, pushed past any other
        shadow it falls into (item 4 of the module docstring).  '+' = clockwise (toward +X')."""
        a0 = self.p.alpha0
        psi = sh.centre_angle + (sh.lo - a0 if tag > 0 else sh.hi + a0)
        others = [s for s, *_ in shadows.values() if s is not sh]
        for _ in range(len(others)):
            moved = False
            for s in others:
                if s.contains(psi):
                    psi = s.centre_angle + (s.lo - a0 if tag > 0 else s.hi + a0)
                    moved = True
            if not moved:
                break
        return wrap_scalar(psi)

    def speed(
        self,
        obs: Observation3D,
        rd: ObstacleReading3D,
        v: FloatArray,
        direction: FloatArray,
        sh: Shadow,
    ) -> float:
        """(3.21) or V_max (``speed_law``), floored at 1.5 ||v_i*|| ((3.9))."""
        vmax = self._spec.v_max
        floor = min(vmax, max(1.5 * _norm(v) + 0.05 * vmax, 0.5 * vmax))
        if self.p.speed_law == "tangent":
            # ||l_J|| = ||v*|| / tan(gamma) = sqrt(d*^2 - r^2): the tangent length to the
            # forecast sphere at r*_min, covered in T_s
            d = max(rd.distance + self._spec.radius, 1e-9)
            r = _norm(v) * self.p.sample_period
            length = math.sqrt(max(d * d - r * r, 0.0))
            return min(vmax, max(length / self.p.sample_period, floor))
        d0, d1, d2 = direction.tolist()
        h0, h1, h2 = obs.heading.tolist()
        cos_b = min(d0 * h0 + d1 * h1 + d2 * h2, 1.0)
        return min(vmax, max(vmax * max(cos_b, 0.0), floor))


register(
    ControllerInfo(
        name=Zhang2020Law.name,
        factory=cast("Callable[..., Any]", Zhang2020Law),
        params_type=Zhang2020Params,
        summary="Thesis Ch. 3: sliding-mode law in the on-line frame with AR prediction (3D)",
        reference="Zhang, thesis Ch. 3 §3.3, eqs. (3.11)-(3.22); ICCAR 2020",
        requires_slower_obstacles=True,
        vehicle="vehicle3d",
    )
)
