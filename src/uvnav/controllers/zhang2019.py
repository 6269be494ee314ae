"""``zhang2019-v1``: the thesis's sliding-mode law for a unicycle among moving, rotating, non-convex
obstacles.

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
  ray from the robot rotated by alpha0 from the direction of r_min toward the passing side
  (Fig. 2.5);
  (c) the forecast circle (2.11) centred at r*_min, its two tangent lines from the robot, the
  forecast vectors l^1, l^2 (2.12)-(2.13), the angles beta^1, beta^2 from the robot's velocity, the
  index J, and the law  u_R = U_max f(l_J, v_R),  V_R = ||l_J|| / T_f  (capped at V_max).

Where the thesis is ambiguous or inconsistent, this implementation chooses as follows (all listed
in docs/thesis-notes.md, where the reasons are given at more length):

1. *Passing side.* '+' means the robot circles the obstacle counter-clockwise (keeps it on its
   left, i.e. passes on the side of L_T away from the mass centre — the shorter way round); the ray
   for r*_min is rotated clockwise by alpha0 for '+', counter-clockwise for '-'.  Where that ray
   misses the body (r_min lies on the silhouette), the silhouette point on that side is used.
2. *Forecast circle radius.* The thesis uses ||v_i|| (how far a boundary point may move in one
   sampling second).  The robot has a body, a static obstacle would give a zero-radius circle that
   steers the robot *onto* the boundary, and a rotating body's boundary moves faster than its mass
   centre, so the radius is ``rho = (||v_i|| + |u_i| R_i) T_f + r_robot + safety_margin``
   (R_i: bounding radius); with T_f = 1 s, u_i = 0 and no body/margin it is the thesis's circle.
3. *Which circles.* For a non-convex body the ray at alpha0 can hit the boundary far *behind* a
   spike that holds r_min, and the boundary may bend toward the robot just beyond r*_min; a tangent
   to the single circle at r*_min then grazes the body.  The robot therefore steers along the
   outermost passing-side tangent over the forecast circles of r*_min, r_min and every boundary
   point within D on the passing side in front of r_min.
4. *Index J.* The thesis defines J by |beta| but writes the comparison with |l| (both tangents have
   the same length, so that comparison never discriminates).  ``tangent_rule="min_beta"`` is the
   literal |beta| rule; the default ``"side"`` takes the tangent on the passing side decided by the
   direction tag, which is what the tag is for and never points into the obstacle.
5. *Sign of f.* With beta measured from v_R to l_J, u_R = -U_max f would turn the robot *away* from
   the forecast vector; the law is used so that the robot turns toward l_J (u_R = +U_max f).  The
   sampled sign function chatters; a boundary layer ``u = U_max sat(beta / (U_max T_c))`` (T_c the
   decision period) is used, identical to the sign law whenever |beta| > U_max T_c.
6. *gamma = asin(||v_i|| / d).* Guarded: when the robot is inside a forecast circle no tangent
   exists; the robot then heads along the limiting direction (perpendicular to the circle's radius
   on the passing side), tilted outward in proportion to the penetration.
7. *Speed.* The literal law is V_R = ||l_J|| / T_f with ||l_J||^2 = d_min^2 - (||v_i|| T_f)^2 (the
   identity below (2.15)), bounded below by ``min_speed`` and by 1.05 ||v_i|| (constraint (2.6)
   needs the robot faster than the obstacle) and above by V_max: ``speed_law="tangent"``.  On the
   Fig. 2.10 scene, whose disc moves the way the robot passes, it collides after
   8.42 m [ev:ch2-notes.fig210_tangent_path_m] of path where the default arrives after
   14.46 m [ev:ch2-notes.fig210_default_path_m], and it is less safe on the random Chapter-2
   scenes (97.5 % [ev:ch2-notes.random_tangent_pct] success against
   99 % [ev:ch2-notes.random_default_pct], seeds 0-199; ``python -m uvnav.experiments.evidence``
   regenerates these figures, docs/thesis-notes.md), so the default is
   ``speed_law="max"`` — V_max in M2 as in M1 — with ``turn_slowdown``: V_R scaled by cos(beta_J)
   (a unicycle cannot follow a direction change faster than U_max; slowing while turning keeps the
   turning radius V_R / U_max small), never below the same floor.
8. *Switching.* M2 is entered when the nearest obstacle is within ``switch_distance`` D *and* in the
   robot's way (its straight run to T, or its run along the current heading, in the obstacle's
   moving frame, comes within the body radius plus margin) — the thesis's robot "only pays attention
   to those obstacles which are in its way".  M2 is left when no obstacle is in the way; the
   thesis's extra "distance > D" cannot be met while following the boundary of a static or slow
   obstacle at clearance < D (the robot would circle it forever).  "Orientates toward the target"
   is achieved by M1's heading law.
9. *Neighbouring obstacles.* The thesis avoids "the nearest obstacle" and excludes narrow gaps
   (Fig. 2.1(c)).  Moving obstacles can still close a gap; bodies nearer to each other than the
   robot needs to pass (2 (r_robot + margin), plus how much they can close in T_f) are avoided as
   one group, with the tag taken from the group's mass centre.
10. *M1 when not facing T.* The thesis's M1 (u_R = 0) presumes the robot faces T; M1 here turns
   toward T with the same bounded heading law, at V_max, slowing only where T lies inside the
   minimum turning circle so that the robot does not orbit the target.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np

from uvnav.controllers.base import (
    ControllerInfo,
    UnicycleController,
    approach_speed,
    check_params,
    heading_rate_toward,
    register,
)
from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.polygons import points_to_segments, polygons_gap
from uvnav.geometry.small import (
    point_segment_distance,
    ray_circle_distance,
    ray_polygon_distance,
    segment_ring_distance,
    wrap,
)
from uvnav.sensors.observation import Observation, ObstacleReading

_DISC_SAMPLES = 24
#: |beta| [rad] up to which T counts as straight ahead in M1: |sin(beta)| < 1e-9 there, so
#: :func:`approach_speed` does not read the distance (nor does M1 compute it)
_ALIGNED = 5e-10
_NO_IDS: frozenset[int] = frozenset()


@dataclass(frozen=True)
class Zhang2019Params:
    """Parameters of ``zhang2019-v1``.

    Attributes:
        alpha0: angle [rad] between the ray to r_min and the ray defining r*_min (Fig. 2.5).
        switch_distance: D [m], the distance to the nearest obstacle at which M2 may start.
        forecast_horizon: T_f [s], the time the forecast circle looks ahead (thesis: 1 s).
        safety_margin: clearance [m] kept beyond the robot's radius.
        tangent_rule: ``"side"`` (tangent on the passing side) or ``"min_beta"`` (|beta| rule).
        threat_horizon: how far ahead [s] the "in the robot's way" test looks along L_T.
        min_speed: floor [m/s] of V_R in M2.
        speed_law: ``"max"`` (V_R = V_max) or ``"tangent"`` (the literal V_R = ||l_J|| / T_f);
            note 7.
        turn_slowdown: scale V_R by cos(beta_J) (not below the speed floor) while turning; note 7.
    """

    alpha0: float = 0.1
    switch_distance: float = 1.5
    forecast_horizon: float = 1.0
    safety_margin: float = 0.15
    tangent_rule: Literal["side", "min_beta"] = "side"
    threat_horizon: float = 4.0
    min_speed: float = 0.1
    speed_law: Literal["tangent", "max"] = "max"
    turn_slowdown: bool = True

    def __post_init__(self) -> None:
        check_params(
            self,
            positive=("alpha0", "switch_distance", "forecast_horizon", "threat_horizon"),
            non_negative=("safety_margin", "min_speed"),
        )
        if self.alpha0 >= 0.5 * np.pi:
            raise ValueError(f"alpha0 must be < pi/2 rad (got {self.alpha0})")
        if not isinstance(self.turn_slowdown, bool):
            raise ValueError(f"turn_slowdown must be a bool (got {self.turn_slowdown!r})")
        if self.tangent_rule not in ("side", "min_beta"):
            raise ValueError(
                f"tangent_rule must be 'side' or 'min_beta' (got {self.tangent_rule!r})"
            )
        if self.speed_law not in ("tangent", "max"):
            raise ValueError(f"speed_law must be 'tangent' or 'max' (got {self.speed_law!r})")


def boundary_samples(reading: ObstacleReading, n_disc: int = _DISC_SAMPLES) -> FloatArray:
    """Boundary points of an obstacle [m]: a polygon's vertices, or ``n_disc`` points on a disc."""
    if reading.is_disc:
        a = np.linspace(-np.pi, np.pi, n_disc, endpoint=False)
        return reading.centre + reading.radius * np.stack([np.cos(a), np.sin(a)], axis=-1)
    return np.asarray(reading.outline, dtype=float)


def _ring_edges(reading: ObstacleReading) -> tuple[FloatArray, FloatArray]:
    pts = boundary_samples(reading)
    return pts, np.concatenate([pts[1:], pts[:1]])


def run_clearance(
    reading: ObstacleReading, ax: float, ay: float, bx: float, by: float, margin: float
) -> float:
    """Distance [m] from the segment ``(ax, ay)``-``(bx, by)`` [m] to the obstacle's body, exact
    up to ``margin``.

    A bounding-circle test first: when even the bounding disc is farther than ``margin`` the
    (underestimated) disc distance is returned without touching the edges.
    """
    c = reading.centre
    dc = point_segment_distance(float(c[0]), float(c[1]), ax, ay, bx, by)
    if reading.is_disc:
        return max(dc - reading.radius, 0.0)
    if dc - reading.bounding_radius > margin:
        return dc - reading.bounding_radius
    if reading.distance == 0.0:  # the robot is inside this body
        return 0.0
    return segment_ring_distance(ax, ay, bx, by, reading.outline)


def body_gap(a: ObstacleReading, b: ObstacleReading) -> float:
    """Distance [m] between two bodies' boundaries (exact for disjoint bodies).

    Obstacles may overlap each other (thesis §2.2 ignores their collisions); overlapping polygons
    give the distance of their boundaries' nearest non-crossing parts, small where it matters.
    """
    centre_gap = math.hypot(*(a.centre - b.centre)) - a.bounding_radius - b.bounding_radius
    if a.is_disc and b.is_disc:
        return max(centre_gap, 0.0)
    if a.is_disc or b.is_disc:
        disc, poly = (a, b) if a.is_disc else (b, a)
        s, e = _ring_edges(poly)
        n = len(s)
        d = points_to_segments(np.broadcast_to(disc.centre, (n, 2)), s, e)
        return max(float(d.min()) - disc.radius, 0.0)
    return polygons_gap(boundary_samples(a), boundary_samples(b))


@dataclass(frozen=True)
class ObstacleGroup:
    """Obstacles avoided as one (note 9), nearest first."""

    members: tuple[ObstacleReading, ...]

    @property
    def nearest(self) -> ObstacleReading:
        return self.members[0]

    @property
    def ids(self) -> frozenset[int]:
        return frozenset(rd.obstacle_id for rd in self.members)

    @property
    def centre(self) -> FloatArray:
        """Mass centre of the group [m] (members weighted by their bounding-disc areas)."""
        if len(self.members) == 1:
            return np.asarray(self.members[0].centre, dtype=float)
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

    def samples(self) -> FloatArray:
        """All members' boundary samples [m]."""
        return np.concatenate([boundary_samples(m) for m in self.members])

    def ray_hit(self, origin: FloatArray, angle: float) -> FloatArray | None:
        """First boundary point of any member on the ray from ``origin`` at ``angle`` [rad]."""
        ox, oy = float(origin[0]), float(origin[1])
        best = math.inf
        for m in self.members:
            if m.is_disc:
                t = ray_circle_distance(
                    ox, oy, angle, float(m.centre[0]), float(m.centre[1]), m.radius
                )
            else:
                t = ray_polygon_distance(ox, oy, angle, m.outline.tolist())
            best = min(best, t)
        if not math.isfinite(best):
            return None
        return np.array([ox + best * math.cos(angle), oy + best * math.sin(angle)])


def group_around(
    first: ObstacleReading, readings: tuple[ObstacleReading, ...], gap: float, horizon: float
) -> ObstacleGroup:
    """Single-linkage group of ``first`` with the readings whose bodies are closer than ``gap`` [m]
    plus how much the pair can close in ``horizon`` [s] at their current speeds (note 9).

    A bounding-circle test prunes the pairs, on arrays for all the readings still ungrouped at
    once (with a 1e-9 m margin, then the exact scalar test), so a group of n bodies costs O(n)
    array passes rather than O(n^2) Python steps; only the survivors get the exact boundary
    distance of :func:`body_gap`.  The members and their order are those of the pairwise scan.
    """
    pool = [rd for rd in readings if rd.obstacle_id != first.obstacle_id]
    members = [first]
    if not pool:
        return ObstacleGroup((first,))
    centres = np.array([rd.centre for rd in pool], dtype=float).reshape(-1, 2)
    radii = np.array([rd.bounding_radius for rd in pool], dtype=float)
    speeds = np.array([rd.speed for rd in pool], dtype=float)
    free = np.ones(len(pool), dtype=bool)
    frontier = [first]
    while frontier and free.any():
        cur = frontier.pop()
        cx, cy = float(cur.centre[0]), float(cur.centre[1])
        reach = gap + (cur.speed + speeds) * horizon + 1e-9
        near = np.hypot(cx - centres[:, 0], cy - centres[:, 1]) - cur.bounding_radius - radii
        linked = []
        for i in np.flatnonzero(free & (near < reach)).tolist():
            rd = pool[i]
            limit = gap + (cur.speed + rd.speed) * horizon
            far = math.hypot(cx - float(rd.centre[0]), cy - float(rd.centre[1]))
            if far - cur.bounding_radius - rd.bounding_radius < limit and body_gap(cur, rd) < limit:
                linked.append(i)
        free[linked] = False
        members.extend(pool[i] for i in linked)
        frontier.extend(pool[i] for i in linked)
    members.sort(key=lambda m: m.distance)
    return ObstacleGroup(tuple(members))


class Zhang2019Controller(UnicycleController):
    """Thesis Ch. 2 law; see the module docstring for the equations and interpretation choices."""

    name: ClassVar[str] = "zhang2019-v1"

    def __init__(self, params: Zhang2019Params | None = None) -> None:
        super().__init__()
        self.params = params or Zhang2019Params()
        self._group_ids: frozenset[int] = frozenset()
        self._tag = 1

    @property
    def direction(self) -> int:
        """Current direction tag: +1 ('+', counter-clockwise round the obstacle) or -1."""
        return self._tag

    def _reset_law(self, rng: np.random.Generator) -> None:
        self._group_ids = _NO_IDS
        self._tag = 1

    # -- the pieces of §2.3 -------------------------------------------------------------------

    def direction_tag(self, position: FloatArray, centre: FloatArray) -> int:
        """Eq. (2.9): +1 when alpha(t0) = angle(L_T -> L_M) >= 0, else -1 (L_M to ``centre``)."""
        to_t = self._goal - position
        to_m = centre - position
        alpha = wrap(math.atan2(to_m[1], to_m[0]) - math.atan2(to_t[1], to_t[0]))
        return 1 if alpha >= 0.0 else -1

    def forecast_centre(self, position: FloatArray, group: ObstacleGroup, tag: int) -> FloatArray:
        """r*_min (Fig. 2.5): first hit of the ray rotated by alpha0 from r_min toward the passing
        side; where the ray misses every body, the silhouette point on the passing side."""
        ref = _reference_angle(position, group.nearest)
        hit = group.ray_hit(position, ref - tag * self.params.alpha0)
        if hit is not None:
            return hit
        px, py = float(position[0]), float(position[1])
        best, best_rel = None, -math.inf
        for x, y in group.samples().tolist():
            rel = -tag * wrap(math.atan2(y - py, x - px) - ref)  # outermost on the passing side
            if rel > best_rel:
                best, best_rel = (x, y), rel
        assert best is not None
        return np.array(best)

    def forecast_radius(self, group: ObstacleGroup) -> float:
        """rho = (||v_i|| + |u_i| R_i) T_f + r_robot + margin [m] (thesis: ||v_i||; note 2)."""
        p = self.params
        return group.boundary_speed * p.forecast_horizon + self._spec.radius + p.safety_margin

    def in_the_way(self, obs: Observation, reading: ObstacleReading, margin: float) -> bool:
        """Is the obstacle in the robot's way (note 8)?

        In the obstacle's moving frame, either the straight run to T at V_max (over
        ``threat_horizon``) or the run along the current heading (over T_f, which covers the turn M1
        would make toward T) passes within ``margin`` [m] of its body.
        """
        if reading.distance <= margin:
            return True
        px, py = float(obs.pose[0]), float(obs.pose[1])
        gx, gy = float(self._goal[0]) - px, float(self._goal[1]) - py
        dist_goal = math.hypot(gx, gy)
        if dist_goal < 1e-9:
            return False
        v_max = self._spec.v_max
        vx, vy = float(reading.velocity[0]), float(reading.velocity[1])
        # the runs in the obstacle's frame, coordinate by coordinate (numpy's operations)
        horizon = min(self.params.threat_horizon, dist_goal / v_max)
        ex = px + (v_max * gx / dist_goal - vx) * horizon
        ey = py + (v_max * gy / dist_goal - vy) * horizon
        if run_clearance(reading, px, py, ex, ey, margin) <= margin:
            return True
        ahead = min(self.params.forecast_horizon, dist_goal / v_max)
        ex = px + (v_max * math.cos(obs.heading) - vx) * ahead
        ey = py + (v_max * math.sin(obs.heading) - vy) * ahead
        return run_clearance(reading, px, py, ex, ey, margin) <= margin

    def passing_points(
        self, position: FloatArray, group: ObstacleGroup, tag: int
    ) -> list[tuple[float, float, float]]:
        """Forecast circles the robot must pass outside (note 3), as ``(x, y, grow)`` [m].

        The circles are centred at r*_min, r_min and the group's polygon vertices within D on the
        passing side in front of r_min, and at the centre of every disc member in front of r_min;
        each has radius ``rho + grow`` (``grow`` is the disc's radius for disc centres, else 0), so
        discs are handled exactly.
        """
        px, py = float(position[0]), float(position[1])
        near = group.nearest
        ref = _reference_angle(position, near)
        reach = self.params.switch_distance
        r_star = self.forecast_centre(position, group, tag)
        circles = [
            (float(r_star[0]), float(r_star[1]), 0.0),
            (float(near.nearest_point[0]), float(near.nearest_point[1]), 0.0),
        ]
        for m in group.members:
            if m.is_disc:
                cx, cy = float(m.centre[0]), float(m.centre[1])
                in_front = abs(wrap(math.atan2(cy - py, cx - px) - ref)) <= 0.5 * math.pi
                if m.distance <= reach and in_front:
                    circles.append((cx, cy, m.radius))
                continue
            for x, y in m.outline.tolist():
                rel = tag * wrap(math.atan2(y - py, x - px) - ref)
                if -0.5 * math.pi <= rel <= 0.0 and math.hypot(x - px, y - py) <= reach:
                    circles.append((x, y, 0.0))
        return circles

    def steering_angle(self, obs: Observation, group: ObstacleGroup) -> float:
        """Direction [rad] of l_J: the outermost passing-side tangent over the forecast circles."""
        pos = obs.position
        px, py = float(pos[0]), float(pos[1])
        tag = self._tag
        rho0 = self.forecast_radius(group)
        ref = _reference_angle(pos, group.nearest)
        literal = self.params.tangent_rule == "min_beta"
        best_angle, best_score = ref, -math.inf
        for cx, cy, grow in self.passing_points(pos, group, tag):
            rho = rho0 + grow
            dist = math.hypot(cx - px, cy - py)
            base = math.atan2(cy - py, cx - px)
            if dist <= rho:  # inside the circle: the limiting direction, tilted outward (note 6)
                tilt = min(0.25 * math.pi, 0.5 * math.pi * (rho - dist) / max(rho, 1e-9))
                angle = base - tag * (0.5 * math.pi + tilt)
            else:
                gamma = math.asin(rho / dist)
                angle = base - tag * gamma
                if literal:  # thesis's |beta| rule: of the two tangents, the one nearer the heading
                    other = base + tag * gamma
                    if abs(wrap(other - obs.heading)) < abs(wrap(angle - obs.heading)):
                        angle = other
            score = -tag * wrap(angle - ref)  # most clockwise of r_min for '+', CCW for '-'
            if score > best_score:
                best_angle, best_score = angle, score
        return wrap(best_angle)

    def forecast_speed(self, group: ObstacleGroup) -> float:
        """V_R = ||l_J|| / T_f, ||l_J||^2 = d_min^2 - (||v_i|| T_f)^2 (eqs. (2.12)-(2.15); note 7)
        [m/s]."""
        p = self.params
        if p.speed_law == "max":
            return self._spec.v_max
        reach = group.speed * p.forecast_horizon
        d = group.nearest.distance
        length = float(np.sqrt(max(d * d - reach * reach, 0.0)))
        floor = min(self._spec.v_max, max(p.min_speed, group.speed * 1.05))
        return float(np.clip(length / p.forecast_horizon, floor, self._spec.v_max))

    def avoidance_command(
        self, obs: Observation, group: ObstacleGroup, period: float
    ) -> UnicycleCommand:
        """M2, eqs. (2.11)-(2.15)."""
        beta = wrap_scalar(self.steering_angle(obs, group) - obs.heading)
        v = self.forecast_speed(group)
        if self.params.turn_slowdown:
            floor = min(self._spec.v_max, max(self.params.min_speed, 1.05 * group.speed))
            v = max(floor, v * max(math.cos(beta), 0.0))
        return UnicycleCommand(v, heading_rate_toward(beta, self._spec.u_max, period))

    def approach_command(self, obs: Observation, period: float) -> UnicycleCommand:
        """M1 (2.16): V_max toward T, turning toward it when not facing it (note 10).

        Where T lies inside the robot's minimum turning circle (radius V_max / U_max) the speed is
        lowered to the largest one whose turning circle passes through T,
        ``U_max d / (2 sin|beta|)``.
        """
        px, py, heading = obs.pose.tolist()
        gx, gy = float(self._goal[0]) - px, float(self._goal[1]) - py
        beta = wrap_scalar(float(np.arctan2(gy, gx)) - heading)
        # the distance matters only when T is off the heading (|sin(beta)| <= |beta|)
        dist = float(np.hypot(gx, gy)) if abs(beta) > _ALIGNED else math.inf
        spec = self._spec
        v = approach_speed(spec.v_max, spec.u_max, dist, beta)
        return UnicycleCommand(v, heading_rate_toward(beta, spec.u_max, period))

    # -- the switching law ---------------------------------------------------------------------

    def act(self, obs: Observation) -> UnicycleCommand:
        period = self.decision_period(obs.time)
        p = self.params
        margin = self._spec.radius + p.safety_margin
        threat = None
        for rd in obs.obstacles:  # nearest first
            if rd.distance > p.switch_distance:
                break
            if self.in_the_way(obs, rd, margin):
                threat = rd
                break
        if threat is None:
            self._mode = "M1"
            self._group_ids = _NO_IDS
            return self.approach_command(obs, period)
        nearby = tuple(rd for rd in obs.obstacles if rd.distance <= 2.0 * p.switch_distance)
        group = group_around(threat, nearby, 2.0 * margin, p.forecast_horizon)
        if self._mode != "M2" or not (group.ids & self._group_ids):
            self._tag = self.direction_tag(obs.position, group.centre)
        self._group_ids = group.ids
        self._mode = "M2"
        return self.avoidance_command(obs, group, period)


def _reference_angle(position: FloatArray, reading: ObstacleReading) -> float:
    """Direction [rad] of r_min from the robot (of the mass centre when the robot is on the
    boundary)."""
    dx = float(reading.nearest_point[0] - position[0])
    dy = float(reading.nearest_point[1] - position[1])
    if math.hypot(dx, dy) < 1e-9:
        dx = float(reading.centre[0] - position[0])
        dy = float(reading.centre[1] - position[1])
    return math.atan2(dy, dx)


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
