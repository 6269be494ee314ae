"""``zhang2019-v1``: the thesis's sliding-mode law for a unicycle among moving, rotating, non-convex obstacles.

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 2, §2.3, eqs. (2.9)-(2.16), Figs. 2.3-2.6 (originally: "A Method for
Collision-free Guidance of Mobile Robots in Unknown Dynamic Environments with Moving Obstacles",
IEEE ROBIO 2019).

The law switches between two modes:

* **M1** (target approaching, eq. (2.16)): full speed V_max toward the target T.
* **M2** (obstacle avoidance, eq. (2.15)), for the nearest obstacle that is in the robot's way:
  (a) direction tag from alpha(t0), the angle of L_M (robot -> mass centre) measured from L_T
  (robot -> target) when avoidance of that obstacle starts (eq. (2.9)): '+' for alpha >= 0, '-'
  otherwise; (b) the nearest boundary point r_min, then r*_min, the first boundary point hit by the
  ray from the robot rotated by alpha0 from the direction of r_min toward the passing side (Fig. 2.5);
  (c) the forecast circle (2.11) centred at r*_min, its two tangent lines from the robot, the
  forecast vectors l^1, l^2 (2.12)-(2.13), the angles beta^1, beta^2 from the robot's velocity, the
  index J, and the law  u_R = U_max f(l_J, v_R),  V_R = ||l_J|| / T_f  (capped at V_max).

Where the thesis is ambiguous or inconsistent, this implementation chooses as follows (all listed
in docs/thesis-notes.md):

1. *Passing side.* '+' means the robot circles the obstacle counter-clockwise (keeps it on its
   left, i.e. passes on the side of L_T away from the mass centre — the shorter way round); the ray
   for r*_min is rotated clockwise by alpha0 for '+', counter-clockwise for '-'.  Where that ray
   misses the body (r_min lies on the silhouette), the silhouette point on that side is used.
2. *Forecast circle radius.* The thesis uses ||v_i|| (how far a boundary point may move in one
   sampling second).  The robot has a body and a static obstacle would give a zero-radius circle
   that steers the robot *onto* the boundary, so the radius used is
   ``rho = ||v_i|| T_f + r_robot + safety_margin``; with T_f = 1 s and no body/margin it is the
   thesis's circle.
3. *Index J.* The thesis defines J by |beta| but writes the comparison with |l| (both tangents have
   the same length, so that comparison never discriminates).  ``tangent_rule="min_beta"`` is the
   literal |beta| rule; the default ``"side"`` takes the tangent on the passing side decided by the
   direction tag, which is what the tag is for and never points into the obstacle.
4. *Sign of f.* With beta measured from v_R to l_J, u_R = -U_max f would turn the robot *away* from
   the forecast vector; the law is used so that the robot turns toward l_J (u_R = +U_max f).  The
   sampled sign function chatters; a boundary layer ``u = U_max sat(beta / (U_max T_c))`` (T_c the
   decision period) is used, identical to the sign law whenever |beta| > U_max T_c.
5. *gamma = asin(||v_i|| / d).* Guarded: when the robot is inside the forecast circle no tangent
   exists; the robot then heads along the limiting direction (perpendicular to r*_min on the
   passing side), tilted outward in proportion to the penetration, at the speed floor.
6. *Speed.* V_R = ||l_J|| / T_f (thesis: the robot reaches the tangent point in one second) is
   bounded below by ``min_speed`` and by the obstacle's speed (constraint (2.6) requires
   ||v_i|| < ||v_R||), and above by V_max.
7. *Switching.* M2 is entered when the nearest obstacle is within ``switch_distance`` D *and* in the
   robot's way (the straight run to T, in the obstacle's moving frame, comes within the body radius
   plus margin of it within ``threat_horizon``) — the thesis's robot "only pays attention to those
   obstacles which are in its way".  M2 is left when the run to T is clear again; the thesis's extra
   "distance > D" cannot be met while following the boundary of a static or slow obstacle at
   clearance < D (the robot would circle it forever), so it is not required.  "Orientates toward the
   target" is achieved by M1's heading law.
8. *M1 when not facing T.* The thesis's M1 (u_R = 0) presumes the robot faces T; M1 here turns
   toward T with the same bounded sliding-mode heading law, at V_max.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
import shapely

from uvnav.controllers.base import ControllerInfo, heading_rate_toward, register
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec
from uvnav.geometry.angles import FloatArray, signed_angle, wrap_scalar
from uvnav.geometry.polygons import (
    angular_extent,
    point_segment_distance,
    polygon_edges,
    ray_polygon_hit,
    segment_nearest,
    segments_min_distance,
)
from uvnav.geometry.tangents import circle_tangents
from uvnav.sensors.observation import Observation, ObstacleReading


@dataclass(frozen=True)
class Zhang2019Params:
    """Parameters of ``zhang2019-v1``.

    Attributes:
        alpha0: angle [rad] between the ray to r_min and the ray defining r*_min (Fig. 2.5).
        switch_distance: D [m], the distance to the nearest obstacle at which M2 may start.
        forecast_horizon: T_f [s], the time the forecast circle looks ahead (thesis: 1 s).
        safety_margin: clearance [m] kept beyond the robot's radius.
        tangent_rule: ``"side"`` (tangent on the passing side) or ``"min_beta"`` (thesis's |beta| rule).
        threat_horizon: how far ahead [s] the "in the robot's way" test looks.
        min_speed: floor [m/s] of V_R in M2.
    """

    alpha0: float = 0.1
    switch_distance: float = 1.5
    forecast_horizon: float = 1.0
    safety_margin: float = 0.15
    tangent_rule: Literal["side", "min_beta"] = "side"
    threat_horizon: float = 4.0
    min_speed: float = 0.1
    speed_law: Literal["tangent", "max"] = "tangent"

    def __post_init__(self) -> None:
        if not 0.0 < self.alpha0 < 0.5 * np.pi:
            raise ValueError(f"alpha0 must be in (0, pi/2) rad (got {self.alpha0})")
        if self.switch_distance <= 0 or self.forecast_horizon <= 0 or self.threat_horizon <= 0:
            raise ValueError("switch_distance, forecast_horizon and threat_horizon must be > 0")
        if self.safety_margin < 0 or self.min_speed < 0:
            raise ValueError("safety_margin and min_speed must be >= 0")
        if self.tangent_rule not in ("side", "min_beta"):
            raise ValueError(f"tangent_rule must be 'side' or 'min_beta' (got {self.tangent_rule!r})")


def obstacle_ray_point(origin: FloatArray, angle: float, reading: ObstacleReading) -> FloatArray | None:
    """First boundary point of the obstacle on the ray from ``origin`` at ``angle`` [rad], or None."""
    if reading.is_disc:
        t = circle_ray(origin, angle, reading.centre, reading.radius)
        return None if t is None else origin + t * np.array([np.cos(angle), np.sin(angle)])
    _, hit = ray_polygon_hit(origin, angle, reading.outline)
    return hit


def circle_ray(origin: FloatArray, angle: float, centre: FloatArray, radius: float) -> float | None:
    """Distance along the unit ray to the first crossing of a circle [m], or None on a miss."""
    d = np.array([np.cos(angle), np.sin(angle)])
    m = centre - origin
    b = float(d @ m)
    c = float(m @ m) - radius * radius
    disc = b * b - c
    if disc < 0:
        return None
    sq = np.sqrt(disc)
    t = b - sq if b - sq >= 0 else b + sq
    return t if t >= 0 else None


def silhouette_point(origin: FloatArray, reading: ObstacleReading, side: int) -> FloatArray:
    """Boundary point grazed by the obstacle's silhouette ray on ``side`` (+1 CCW, -1 CW) [m]."""
    to_c = reading.centre - origin
    ref = float(np.arctan2(to_c[1], to_c[0]))
    if reading.is_disc:
        tg = circle_tangents(origin, reading.centre, reading.radius)
        return tg.points[0] if side > 0 else tg.points[1]
    lo, hi = angular_extent(origin, reading.outline, ref)
    rel = np.arctan2(reading.outline[:, 1] - origin[1], reading.outline[:, 0] - origin[0]) - ref
    rel = np.pi - np.mod(np.pi - rel, 2.0 * np.pi)
    target = hi if side > 0 else lo
    return np.asarray(reading.outline[int(np.argmin(np.abs(rel - target)))], dtype=float)


def boundary_samples(reading: ObstacleReading, n_disc: int = 24) -> FloatArray:
    """Boundary points of an obstacle [m]: a polygon's vertices, or ``n_disc`` points on a disc."""
    if reading.is_disc:
        a = np.linspace(-np.pi, np.pi, n_disc, endpoint=False)
        return reading.centre + reading.radius * np.stack([np.cos(a), np.sin(a)], axis=-1)
    return reading.outline


def obstacle_blocks_segment(a: FloatArray, b: FloatArray, reading: ObstacleReading, margin: float) -> bool:
    """True when the segment ``a``-``b`` comes within ``margin`` [m] of the obstacle's body."""
    if reading.is_disc:
        return point_segment_distance(reading.centre, a, b) <= reading.radius + margin
    s, e = polygon_edges(reading.outline)
    return segments_min_distance(a, b, s, e) <= margin or reading.distance == 0.0


@dataclass(frozen=True)
class ObstacleGroup:
    """Obstacles avoided as one: bodies closer to each other than the robot can pass between.

    The thesis avoids "the nearest obstacle" and excludes narrow gaps and U-traps (Fig. 2.1(c)); two
    moving obstacles can still come close enough that the passing side chosen for one runs into the
    other, so bodies whose gap is below ``2 (r_robot + margin)`` are grouped and the group is avoided
    like one non-convex obstacle (docs/thesis-notes.md).  Members are sorted nearest first.
    """

    members: tuple[ObstacleReading, ...]

    @property
    def nearest(self) -> ObstacleReading:
        return self.members[0]

    @property
    def ids(self) -> frozenset[int]:
        return frozenset(m.obstacle_id for m in self.members)

    @property
    def centre(self) -> FloatArray:
        """Mass centre of the group [m] (members weighted by their bounding-disc areas)."""
        w = np.array([max(m.bounding_radius, 1e-6) ** 2 for m in self.members])
        c = np.array([m.centre for m in self.members])
        return np.asarray((w[:, None] * c).sum(axis=0) / w.sum(), dtype=float)

    @property
    def speed(self) -> float:
        """Fastest translation ||v_i|| among the members [m/s]."""
        return max(m.speed for m in self.members)

    @property
    def boundary_speed(self) -> float:
        """Bound on how fast any boundary point of a member moves [m/s]: ||v_i|| + |u_i| R_i."""
        return max(m.speed + abs(m.angular_velocity) * m.bounding_radius for m in self.members)


def body_gap(a: ObstacleReading, b: ObstacleReading) -> float:
    """Distance [m] between two obstacle bodies (0 when they touch or overlap)."""
    if a.is_disc and b.is_disc:
        return max(float(np.hypot(*(a.centre - b.centre))) - a.radius - b.radius, 0.0)
    if a.is_disc or b.is_disc:
        disc, poly = (a, b) if a.is_disc else (b, a)
        s, e = polygon_edges(poly.outline)
        d, _ = segment_nearest(disc.centre, s, e)
        return max(float(d.min()) - disc.radius, 0.0)
    return float(shapely.distance(shapely.Polygon(a.outline), shapely.Polygon(b.outline)))


def group_around(
    first: ObstacleReading, readings: tuple[ObstacleReading, ...], gap: float, reach: float, horizon: float
) -> ObstacleGroup:
    """Single-linkage group of ``first`` with the readings within ``reach`` [m] whose bodies are closer
    than ``gap`` [m] plus how much the two can close in ``horizon`` [s] at their current speeds."""
    pool = [rd for rd in readings if rd.obstacle_id != first.obstacle_id and rd.distance <= reach]
    members = [first]
    frontier = [first]
    while frontier and pool:
        cur = frontier.pop()
        close = [rd for rd in pool if body_gap(cur, rd) < gap + (cur.speed + rd.speed) * horizon]
        for rd in close:
            pool.remove(rd)
        members.extend(close)
        frontier.extend(close)
    members.sort(key=lambda m: m.distance)
    return ObstacleGroup(tuple(members))


class Zhang2019Controller:
    """Thesis Ch. 2 law; see the module docstring for the equations and interpretation choices."""

    name: ClassVar[str] = "zhang2019-v1"

    def __init__(self, params: Zhang2019Params | None = None) -> None:
        self.params = params or Zhang2019Params()
        self.oracle = False
        self._spec = UnicycleSpec(1.0, 1.0)
        self._goal = np.zeros(2)
        self._mode = "M1"
        self._group_ids: frozenset[int] = frozenset()
        self._tag = 1
        self._last_t: float | None = None

    @property
    def mode(self) -> str:
        return self._mode

    @property
    def target_ids(self) -> frozenset[int]:
        """Ids of the obstacles avoided in M2 (empty in M1)."""
        return self._group_ids

    def reset(self, spec: UnicycleSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        self._spec = spec
        self._goal = np.asarray(goal, dtype=float)
        self._mode = "M1"
        self._group_ids = frozenset()
        self._tag = 1
        self._last_t = None

    # -- the pieces of §2.3 -------------------------------------------------------------------

    def direction_tag(self, position: FloatArray, centre: FloatArray) -> int:
        """Eq. (2.9): +1 when alpha(t0) = angle(L_T -> L_M) >= 0, else -1 (L_M toward ``centre``)."""
        alpha = float(signed_angle(self._goal - position, centre - position))
        return 1 if alpha >= 0.0 else -1

    def forecast_centre(self, position: FloatArray, group: ObstacleGroup, tag: int) -> FloatArray:
        """r*_min (Fig. 2.5): first hit of the ray rotated by alpha0 from r_min toward the passing side.

        Where the ray misses every body (r_min is on the silhouette), the silhouette point on the
        passing side is used.
        """
        near = group.nearest
        to_near = near.nearest_point - position
        if float(np.hypot(*to_near)) < 1e-9:  # robot on the boundary: use the mass-centre direction
            to_near = near.centre - position
        ray = float(np.arctan2(to_near[1], to_near[0])) - tag * self.params.alpha0
        hits = [h for h in (obstacle_ray_point(position, ray, m) for m in group.members) if h is not None]
        if hits:
            return min(hits, key=lambda h: float(np.hypot(*(h - position))))
        pts = np.concatenate([boundary_samples(m) for m in group.members])
        rel = signed_angle(to_near, pts - position)
        return np.asarray(pts[int(np.argmin(rel)) if tag > 0 else int(np.argmax(rel))], dtype=float)

    def forecast_radius(self, group: ObstacleGroup) -> float:
        """rho = (||v_i|| + |u_i| R_i) T_f + r_robot + margin [m] (thesis: ||v_i||, see note 2).

        A boundary point of a body rotating at u_i about its mass centre moves up to |u_i| R_i faster
        than the centre (R_i its bounding radius); the thesis bounds this through (2.8), the circle
        here covers it explicitly.
        """
        p = self.params
        return group.boundary_speed * p.forecast_horizon + self._spec.radius + p.safety_margin

    def in_the_way(self, obs: Observation, reading: ObstacleReading, margin: float) -> bool:
        """Is the obstacle in the robot's way (note 7)?

        True when, in the obstacle's moving frame, either the straight run to T at V_max (over
        ``threat_horizon``) or the run along the current heading (over one forecast horizon T_f,
        which covers the turn M1 would make toward T) passes within ``margin`` [m] of its body.
        """
        position = obs.position
        to_goal = self._goal - position
        dist_goal = float(np.hypot(*to_goal))
        if reading.distance <= margin:
            return True
        if dist_goal < 1e-9:
            return False
        v_max = self._spec.v_max
        rel_goal = v_max * to_goal / dist_goal - reading.velocity
        horizon = min(self.params.threat_horizon, dist_goal / v_max)
        if obstacle_blocks_segment(position, position + rel_goal * horizon, reading, margin):
            return True
        rel_head = v_max * np.array([np.cos(obs.heading), np.sin(obs.heading)]) - reading.velocity
        ahead = min(self.params.forecast_horizon, dist_goal / v_max)
        return obstacle_blocks_segment(position, position + rel_head * ahead, reading, margin)

    def passing_points(self, position: FloatArray, group: ObstacleGroup, tag: int) -> FloatArray:
        """Centres of the forecast circles the robot must pass outside.

        r*_min and r_min (the thesis's points) and every boundary point of the group within the
        switching distance D that lies on the passing side of r_min and in front of it (at most 90
        degrees from the direction of r_min).  For a non-convex body the ray at alpha0 can hit a part
        of the boundary far *behind* a spike holding r_min, or the boundary may bend toward the robot
        just past r*_min; a tangent to the single circle at r*_min would then graze it
        (docs/thesis-notes.md), so the outermost tangent over all these circles is used.
        """
        near = group.nearest
        pts = [self.forecast_centre(position, group, tag), near.nearest_point]
        to_near = near.nearest_point - position
        if float(np.hypot(*to_near)) < 1e-9:
            to_near = near.centre - position
        boundary = np.concatenate([boundary_samples(m) for m in group.members])
        offsets = boundary - position
        rel = signed_angle(to_near, offsets) * tag
        dist = np.hypot(offsets[:, 0], offsets[:, 1])
        keep = (rel <= 0.0) & (rel >= -0.5 * np.pi) & (dist <= self.params.switch_distance)
        pts.extend(boundary[keep])
        return np.asarray(pts, dtype=float)

    def avoidance_command(self, obs: Observation, group: ObstacleGroup, period: float) -> UnicycleCommand:
        """M2, eqs. (2.11)-(2.15): steer along the outermost forecast-circle tangent on the passing side."""
        p = self.params
        pos = obs.position
        rho = self.forecast_radius(group)
        centres = self.passing_points(pos, group, self._tag)
        ref = group.nearest.nearest_point - pos
        if float(np.hypot(*ref)) < 1e-9:
            ref = group.nearest.centre - pos
        heading_vec = np.array([np.cos(obs.heading), np.sin(obs.heading)])
        best: tuple[float, float] | None = None  # (score, angle)
        for centre in centres:
            tg = circle_tangents(pos, centre, rho)
            if tg.inside:
                base = float(np.arctan2(centre[1] - pos[1], centre[0] - pos[0]))
                dist = float(np.hypot(*(centre - pos)))
                tilt = min(0.25 * np.pi, 0.5 * np.pi * (rho - dist) / max(rho, 1e-9))
                angle = wrap_scalar(base - self._tag * (0.5 * np.pi + tilt))
            else:
                # tangent 0 is the CCW one (base + gamma), tangent 1 the CW one
                if p.tangent_rule == "side":
                    j = 1 if self._tag > 0 else 0
                else:
                    betas = [abs(float(signed_angle(heading_vec, tg.points[k] - pos))) for k in (0, 1)]
                    j = 0 if betas[0] <= betas[1] else 1
                angle = float(tg.angles[j])
            # outermost on the passing side: most clockwise from r_min for '+', most CCW for '-'
            score = -self._tag * float(signed_angle(ref, np.array([np.cos(angle), np.sin(angle)])))
            if best is None or score > best[0]:
                best = (score, angle)
        assert best is not None
        _, angle = best
        beta = wrap_scalar(angle - obs.heading)
        u = heading_rate_toward(beta, self._spec.u_max, period)
        return UnicycleCommand(self.forecast_speed(group), u)

    def forecast_speed(self, group: ObstacleGroup) -> float:
        """V_R = ||l_J|| / T_f with ||l_J||^2 = d_min^2 - (||v_i|| T_f)^2 (eqs. (2.12)-(2.15)) [m/s].

        The thesis's identity d_min^2 = ||v_i||^2 + ||l_J||^2 is used as written (forecast radius
        ||v_i|| T_f, distance d_min to r_min), bounded below by ``min_speed`` and by 1.05 ||v_i||
        (constraint (2.6)) and above by V_max.  ``speed_law="max"`` drives at V_max instead.
        """
        p = self.params
        if p.speed_law == "max":
            return self._spec.v_max
        reach = group.speed * p.forecast_horizon
        d = group.nearest.distance
        length = float(np.sqrt(max(d * d - reach * reach, 0.0)))
        floor = min(self._spec.v_max, max(p.min_speed, group.speed * 1.05))
        return float(np.clip(length / p.forecast_horizon, floor, self._spec.v_max))

    # -- the switching law ---------------------------------------------------------------------

    def act(self, obs: Observation) -> UnicycleCommand:
        period = 0.1 if self._last_t is None else max(obs.time - self._last_t, 1e-6)
        self._last_t = obs.time
        p = self.params
        pos = obs.position
        body_margin = self._spec.radius + p.safety_margin
        threat = next(
            (rd for rd in obs.obstacles if rd.distance <= p.switch_distance and self.in_the_way(obs, rd, body_margin)),
            None,
        )
        if threat is not None:
            group = group_around(
                threat, obs.obstacles, 2.0 * body_margin, 2.0 * p.switch_distance, p.forecast_horizon
            )
            if self._mode != "M2" or not (group.ids & self._group_ids):
                self._tag = self.direction_tag(pos, group.centre)
            self._group_ids = group.ids
            self._mode = "M2"
            return self.avoidance_command(obs, group, period)
        self._mode = "M1"
        self._group_ids = frozenset()
        return self.approach_command(obs, period)

    def approach_command(self, obs: Observation, period: float) -> UnicycleCommand:
        """M1 (2.16): V_max toward T, turning toward it when not facing it (note 8).

        When T lies inside the robot's minimum turning circle (radius V_max / U_max) the speed is
        lowered to the largest one whose turning circle passes through T, ``U_max d / (2 sin|beta|)``,
        so the robot does not orbit the target.
        """
        to_goal = self._goal - obs.position
        dist = float(np.hypot(*to_goal))
        beta = wrap_scalar(float(np.arctan2(to_goal[1], to_goal[0])) - obs.heading)
        v = self._spec.v_max
        sin_b = abs(np.sin(beta))
        if sin_b > 1e-9:
            v = min(v, self._spec.u_max * dist / (2.0 * sin_b))
        if abs(beta) > 0.5 * np.pi:  # target behind: turn on the spot's tightest circle
            v = min(v, self._spec.u_max * dist / 2.0)
        return UnicycleCommand(v, heading_rate_toward(beta, self._spec.u_max, period))


register(
    ControllerInfo(
        name="zhang2019-v1",
        factory=Zhang2019Controller,
        params_type=Zhang2019Params,
        summary="Thesis Ch. 2: M1/M2 sliding-mode law with forecast-circle tangents (ROBIO 2019).",
        reference="Y. Zhang, thesis Ch. 2, eqs. (2.9)-(2.16)",
        requires_slower_obstacles=True,
    )
)
