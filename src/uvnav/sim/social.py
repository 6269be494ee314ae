"""Social metrics of a 2D episode: how the robot treats the pedestrians of a crowd scene.

Crowd-navigation papers report, beside success and collisions, how close the robot came to people
and how often it made them uncomfortable.  The 2D world (:class:`uvnav.sim.episode.World2D`, any
planar vehicle) keeps the numbers below with :class:`SocialTracker` at every integration step;
every other vehicle kind reports them as ``None``.

**Who is a pedestrian.**  The scene schema has no pedestrian flag, so the rule is structural: a
pedestrian is an obstacle whose body is a *disc* and whose motion model can move it
(``motion.speed_bound() > 0``) — :func:`pedestrian_ids`.  That covers the two kinds of people the
scenes hold: replayed ETH/UCY walkers (``crowd:`` section, :mod:`uvnav.scenarios.pedestrians`) and
CrowdNav's ORCA humans (``orca_crowd`` motion, :mod:`uvnav.obstacles.crowd`); moving discs of other
scenes count too (they are the same thing to the robot), static discs and polygons never do.  A
replayed pedestrian outside its track is parked 1 km away and so never comes close.

**Gap.**  The gap to a pedestrian is the distance between the robot's disc and the pedestrian's
disc, ``|c - p| - r_ped - R`` [m] (negative on overlap), evaluated in the same floating-point order
as the collision check, so in a scene whose only bodies are pedestrians ``min_separation`` equals
``min_clearance`` bit for bit.

Metrics (``None`` in a scene without pedestrians, except where said):

``min_separation`` [m]
    smallest gap to any pedestrian over every integration step of the episode, the initial state
    included (CrowdNav's "minimum separation distance"; Chen et al., ICRA 2019).
``too_close_time`` [s]
    ``dt`` times the number of integration steps whose end state has a gap < 0.2 m,
    CrowdNav's discomfort distance (``discomfort_dist = 0.2`` in its ``env.config``).
``too_close_frequency``
    share of the episode's decisions whose decision period (the integration steps the decision's
    command is held over) holds a state with a gap < 0.2 m: CrowdNav's per-step discomfort count
    ("frequency of being in danger") divided by the number of decision steps.  An overlap
    (collision) counts as too close.
``intrusion_time`` [s]
    ``dt`` times the number of integration steps whose end state has a gap < 0.45 m, the outer
    edge of Hall's intimate zone (E. T. Hall, *The Hidden Dimension*, 1966: intimate distance up to
    18 in ≈ 0.45 m) — time with a pedestrian inside the robot's personal space.
``intrusion_ratio``
    share of the integration steps (the initial state left out) whose end state puts the robot's
    disc on the disc of a *visible* pedestrian as that pedestrian will be over the next 1.25 s:
    ``|c - (p + v k dt)| - r_ped - R < 0`` for some ``k = 1 .. K``, ``K = round(1.25 / dt)``
    (at least 1), with ``p`` and ``v`` the pedestrian's centre and velocity at that step.  This
    is the intrusion ratio of Liu et al. (ICRA 2023, "Intention aware robot crowd navigation
    with attention-based interaction graph"; CrowdNav++), whose simulator checks the robot's
    position against each visible human's positions at the next five 0.25 s steps, within the
    radius sum (0.3 + 0.3 = 0.6 m; here each pedestrian's own radius).  CrowdNav++ takes the
    humans' *true* future positions from its simulator; the world here cannot know the future
    of humans that react (to each other, or to a visible robot), so the forecast is constant
    velocity, which is also what a robot could compute.  Visible: the pedestrian's disc within
    the robot's sensing range, ``|c - p| - r_ped <= sensing_range`` (the exact sensor's
    rule); an absent pedestrian never counts.
``personal_space_time`` [s], ``min_time_to_collision`` [s]
    time with a gap < 0.5 m, and the smallest constant-velocity time to collision with a
    pedestrian (:mod:`uvnav.sim.comfort`, which also defines ``heading_irregularity`` and
    ``jerk``, metrics of every 2D episode).
``path_irregularity`` [rad/m]
    total absolute heading change divided by the path length: ``sum_k |Δθ_k| / L`` over the
    integration steps (unicycle: ``sum |u_R| dt``, the exact rotation of each step; holonomic
    robot: the wrapped change of the direction of motion each time it changes).  Defined for every
    2D episode (with or without pedestrians); ``None`` when the robot did not move.  This is the
    "path irregularity" of Guzzi et al. (ICRA 2013, "Human-friendly robot navigation in dynamic
    environments") *without* their subtraction of the rotation needed to face the target, so it
    is never negative and needs no goal.
``collision_by``
    at a collision, who closed the gap: ``"robot"`` or ``"pedestrian"`` (``"obstacle"`` when the
    body is not a pedestrian); ``None`` without collision.  For a *disc* body (every pedestrian)
    it is judged over the last second before the contact (:data:`BLAME_WINDOW`,
    :class:`GapHistory`): at each integration step of that window the gap between the two
    centres closes by the robot's displacement along the line to the body's centre plus the
    body's displacement along the line to the robot; the robot closed the gap when its part of
    the closing, summed over the window, is larger than the body's.  A robot that turns into a
    person in its last step but had been drawing away is then not blamed for the person's
    approach, nor is a person who side-steps at the last instant into a robot that drove at them.
    A *polygon* is judged at the contact instant, where the velocity of its touching point
    (translation plus rotation) is known: ``"robot"`` when the robot's velocity component toward
    the body's nearest boundary point is larger than that point's velocity component toward the
    robot.  Where the world found the contact along the step, the instant is the first contact
    (:meth:`uvnav.sim.swept.SweptClearance.contact_by`), else the step's end.  A body that did
    not exist one step before (a replayed pedestrian whose recorded track starts in contact with
    the robot) closed the gap by appearing there: ``"appeared"``, whatever the motion (no one
    drove into it).  Set for every 2D scene, with or without pedestrians.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from uvnav.obstacles.bodies import DiscBody
from uvnav.obstacles.obstacle import Obstacle, ObstacleField
from uvnav.sim.comfort import PERSONAL_DISTANCE, time_to_collision

#: CrowdNav's discomfort distance [m] (gap below which the robot is "too close")
DISCOMFORT_DISTANCE = 0.2
#: Hall's intimate distance [m] (gap below which a pedestrian intrudes on the robot's space)
INTIMATE_DISTANCE = 0.45
#: how far ahead the intrusion ratio forecasts the pedestrians [s] (CrowdNav++: 5 x 0.25 s)
INTRUSION_HORIZON = 1.25


def pedestrian_ids(obstacles: Sequence[Obstacle]) -> np.ndarray:
    """Indices of the pedestrians of ``obstacles``: disc bodies whose motion can move them
    (``speed_bound() > 0``; see the module docstring)."""
    ids = [
        j
        for j, ob in enumerate(obstacles)
        if isinstance(ob.body, DiscBody) and float(ob.motion.speed_bound()) > 0.0
    ]
    return np.asarray(ids, dtype=np.intp)


class SocialTracker:
    """Gap to the nearest pedestrian at every integration step of a 2D episode.

    Args:
        ids: the pedestrians' indices among the field's obstacles (:func:`pedestrian_ids`,
            not empty).
        radii: (k,) disc radius of every obstacle [m] (``FieldTemplate.radii``).
        robot_radius: the robot's radius [m].
        dt: integration step [s].
        ratio: integration steps per decision.
        sensing_range: the robot's sensing range [m]: only pedestrians within it count for the
            intrusion ratio.
    """

    __slots__ = (
        "_all",
        "_close_periods",
        "_close_steps",
        "_forecast",
        "_ids",
        "_intruded_steps",
        "_intrusion_steps",
        "_last_period",
        "_personal_steps",
        "_radii",
        "_radius",
        "_range",
        "_steps",
        "dt",
        "min_separation",
        "min_ttc",
        "ratio",
    )

    def __init__(
        self,
        ids: np.ndarray,
        radii: np.ndarray,
        robot_radius: float,
        dt: float,
        ratio: int,
        sensing_range: float = math.inf,
    ) -> None:
        self._ids = ids
        self._all = len(ids) == len(radii)
        self._radii = radii if self._all else radii.take(ids)
        self._radius = float(robot_radius)
        self.dt = float(dt)
        self.ratio = int(ratio)
        self.min_separation = math.inf
        self._close_steps = 0
        self._intrusion_steps = 0
        self._close_periods = 0
        self._last_period = -1
        self._range = float(sensing_range)
        k = max(1, round(INTRUSION_HORIZON / self.dt))
        self._forecast = np.arange(1, k + 1, dtype=float)[:, None] * self.dt  # (K, 1) [s]
        self._steps = 0
        self._intruded_steps = 0
        self._personal_steps = 0  # steps after the first with a gap < PERSONAL_DISTANCE
        self.min_ttc = math.inf  # smallest time to collision with a pedestrian [s]

    def gap(self, fld: ObstacleField, px: float, py: float) -> float:
        """Smallest gap [m] between the robot's disc at ``(px, py)`` and a pedestrian's."""
        c = fld.centres if self._all else fld.centres.take(self._ids, axis=0)
        # the collision check's order: (|p - c| - r_ped) - R
        g = np.hypot(px - c[:, 0], py - c[:, 1]) - self._radii - self._radius
        present = fld.present
        if present is not None:  # an absent pedestrian is nobody (not a parked one 1 km away)
            g = np.where(present if self._all else present.take(self._ids), g, np.inf)
        return float(g.min()) if len(g) else math.inf

    def observe(
        self,
        fld: ObstacleField,
        px: float,
        py: float,
        step: int,
        velocity: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        """Account for the state after integration step ``step`` (0: the initial state, which
        counts for the minimum only); ``velocity``: the robot's [m/s] (time to collision)."""
        g = self.gap(fld, px, py)
        if g < self.min_separation:
            self.min_separation = g
        if step > 0:
            self._steps += 1
            self._intruded_steps += self.intrudes(fld, px, py)
            self._personal_steps += g < PERSONAL_DISTANCE
            ttc = self.time_to_collision(fld, px, py, velocity)
            if ttc < self.min_ttc:
                self.min_ttc = ttc
        if step > 0 and g < INTIMATE_DISTANCE:
            self._intrusion_steps += 1
            if g < DISCOMFORT_DISTANCE:
                self._close_steps += 1
                period = (step - 1) // self.ratio
                if period != self._last_period:
                    self._last_period = period
                    self._close_periods += 1

    def intrudes(self, fld: ObstacleField, px: float, py: float) -> bool:
        """Whether the robot's disc at ``(px, py)`` lies on a visible pedestrian's disc as a
        constant-velocity forecast puts it over the next :data:`INTRUSION_HORIZON` seconds
        (module docstring, ``intrusion_ratio``)."""
        ids = None if self._all else self._ids
        c = fld.centres if ids is None else fld.centres.take(ids, axis=0)
        v = fld.velocities if ids is None else fld.velocities.take(ids, axis=0)
        seen = np.hypot(px - c[:, 0], py - c[:, 1]) - self._radii <= self._range
        present = fld.present
        if present is not None:
            seen &= present if ids is None else present.take(ids)
        if not seen.any():
            return False
        c, v, r = c[seen], v[seen], self._radii[seen]
        fx = c[:, 0] + v[:, 0] * self._forecast  # (K, n) forecast centres
        fy = c[:, 1] + v[:, 1] * self._forecast
        return bool((np.hypot(px - fx, py - fy) - r - self._radius < 0.0).any())

    def time_to_collision(
        self, fld: ObstacleField, px: float, py: float, velocity: tuple[float, float]
    ) -> float:
        """Smallest constant-velocity time to collision [s] of the robot's disc at ``(px, py)``
        moving at ``velocity`` [m/s] with a present pedestrian's
        (:func:`uvnav.sim.comfort.time_to_collision`); ``inf`` when on course with none."""
        ids = None if self._all else self._ids
        c = fld.centres if ids is None else fld.centres.take(ids, axis=0)
        v = fld.velocities if ids is None else fld.velocities.take(ids, axis=0)
        r = self._radii + self._radius
        present = fld.present
        if present is not None:
            here = present if ids is None else present.take(ids)
            c, v, r = c[here], v[here], r[here]
        rel_v = v - np.asarray(velocity, dtype=float)
        ttc = time_to_collision(c - (px, py), rel_v, r)
        return float(ttc.min()) if len(ttc) else math.inf

    @property
    def personal_space_time(self) -> float:
        """Time with a gap < :data:`uvnav.sim.comfort.PERSONAL_DISTANCE` [s]."""
        return self.dt * self._personal_steps

    @property
    def intrusion_ratio(self) -> float:
        """Share of the integration steps with an intrusion (:meth:`intrudes`); 0 before any."""
        return self._intruded_steps / self._steps if self._steps else 0.0

    @property
    def too_close_time(self) -> float:
        """Time with a gap < :data:`DISCOMFORT_DISTANCE` [s]."""
        return self._close_steps * self.dt

    @property
    def intrusion_time(self) -> float:
        """Time with a gap < :data:`INTIMATE_DISTANCE` [s]."""
        return self._intrusion_steps * self.dt

    def too_close_frequency(self, decisions: int) -> float:
        """Share of ``decisions`` whose period held a gap < :data:`DISCOMFORT_DISTANCE`."""
        return min(self._close_periods / decisions, 1.0) if decisions > 0 else 0.0


#: the cause of a collision with a body that appeared in contact (its track starts there)
APPEARED = "appeared"
#: how far back before a contact the blame of a collision with a disc looks [s]
BLAME_WINDOW = 1.0


class GapHistory:
    """The robot's centre and every body's centre at the last integration steps of a 2D episode,
    :data:`BLAME_WINDOW` of them and one more (a ring), for :meth:`robot_closed`.

    Args:
        n_bodies: the bodies of the field.
        dt: integration step [s].
    """

    __slots__ = ("_bodies", "_count", "_present", "_robot", "_size")

    def __init__(self, n_bodies: int, dt: float) -> None:
        self._size = size = max(1, round(BLAME_WINDOW / dt)) + 1
        self._robot = np.zeros((size, 2))
        self._bodies = np.zeros((size, n_bodies, 2))
        self._present = np.ones((size, n_bodies), dtype=bool)
        self._count = 0

    def push(self, x: float, y: float, centres: np.ndarray, present: np.ndarray | None) -> None:
        """Keep the state after a step: the robot at ``(x, y)`` [m], the bodies' ``centres``
        (k, 2) [m], which of them exist (``None``: all)."""
        i = self._count % self._size
        self._robot[i] = (x, y)
        self._bodies[i] = centres
        self._present[i] = True if present is None else present
        self._count += 1

    def shares(self, body: int) -> tuple[float, float]:
        """How much of the closing of the centre-to-centre distance to ``body`` over the window
        the robot did and the body did [m] (module docstring, ``collision_by``); the steps
        where the body is absent at either end are left out.

        >>> h = GapHistory(1, 0.5)
        >>> for k in range(3):  # the robot walks 1 m/s at a body that stands 3 m ahead
        ...     h.push(0.5 * k, 0.0, np.array([[3.0, 0.0]]), None)
        >>> h.shares(0)
        (1.0, 0.0)
        """
        m = min(self._count, self._size)
        order = [(self._count - m + i) % self._size for i in range(m)]
        r, c, there = self._robot[order], self._bodies[order, body], self._present[order, body]
        d = c[:-1] - r[:-1]
        norm = np.hypot(d[:, 0], d[:, 1])
        toward = d / np.where(norm > 0.0, norm, 1.0)[:, None]
        both = there[:-1] & there[1:] & (norm > 0.0)
        robot = ((r[1:] - r[:-1]) * toward).sum(axis=1)
        moved = -((c[1:] - c[:-1]) * toward).sum(axis=1)
        return float(robot[both].sum()), float(moved[both].sum())

    def robot_closed(self, body: int) -> bool:
        """Whether the robot did more of the closing to ``body`` over the window than it did."""
        robot, moved = self.shares(body)
        return robot > moved


def collision_by(
    fld: ObstacleField,
    px: float,
    py: float,
    robot_velocity: tuple[float, float],
    pedestrians: np.ndarray,
    *,
    was_present: np.ndarray | None = None,
    history: GapHistory | None = None,
) -> str:
    """Who closed the gap at a collision of the robot at ``(px, py)`` (module docstring).

    Args:
        fld: the field at the collision step.
        robot_velocity: the robot's velocity ``(vx, vy)`` [m/s] at that step.
        pedestrians: indices of the pedestrians (:func:`pedestrian_ids`).
        was_present: per body, whether it existed one step before (``None``: all did).
        history: the last second of the episode, with this step (a disc is judged over it;
            ``None``: at this step, as a polygon is).

    Returns:
        ``"robot"``, ``"pedestrian"``, ``"obstacle"`` or ``"appeared"`` (the body did not exist
        one step before).
    """
    q = fld.query((px, py), 0.0, nearest=True)
    j = int(q.signed.argmin())
    body = int(q.ids[j])
    centre = (float(fld.centres[body, 0]), float(fld.centres[body, 1]))
    disc = bool(fld.template.radii[body] > 0)
    touch = (float(q.nearest[j, 0]), float(q.nearest[j, 1]))
    if was_present is not None and not bool(was_present[body]):
        return APPEARED
    if disc and history is not None:
        return blame(history.robot_closed(body), body, pedestrians)
    robot = robot_closed(
        (px, py), centre, touch, disc, bool(q.inside[j]), robot_velocity,
        (float(fld.velocities[body, 0]), float(fld.velocities[body, 1])),
        float(fld.angular_velocities[body]),
    )  # fmt: skip
    return blame(robot, body, pedestrians)


def blame(robot: bool, body: int, pedestrians: np.ndarray) -> str:
    """The cause of a collision with ``body``: ``"robot"`` when the robot closed the gap, else
    ``"pedestrian"`` or ``"obstacle"`` (``pedestrians``: the pedestrians' indices)."""
    if robot:
        return "robot"
    return "pedestrian" if bool(np.isin(body, pedestrians)) else "obstacle"


def robot_closed(
    point: tuple[float, float],
    centre: tuple[float, float],
    touch: tuple[float, float],
    disc: bool,
    inside: bool,
    robot_velocity: tuple[float, float],
    body_velocity: tuple[float, float],
    omega: float,
) -> bool:
    """Whether the robot at ``point`` closed the gap to a body (centre ``centre``, nearest
    boundary point ``touch``, the robot's centre ``inside`` it or not) faster than the body did
    (module docstring, ``collision_by``): velocities [m/s], the body's rotation rate [rad/s]."""
    px, py = point
    cx, cy = centre
    # the touching point: a disc's centre (its rotation moves its boundary tangentially, never
    # along the normal), a polygon's nearest boundary point
    tx, ty = (cx, cy) if disc else touch
    nx, ny = tx - px, ty - py
    if inside and not disc:
        nx, ny = -nx, -ny  # the robot's centre is inside: the body lies behind the boundary
    norm = math.hypot(nx, ny)
    if norm == 0.0:  # no direction to close along (centre on the boundary or the centre)
        nx, ny, norm = cx - px, cy - py, max(math.hypot(cx - px, cy - py), 1.0)
    nx, ny = nx / norm, ny / norm
    bvx = body_velocity[0] - omega * (ty - cy)
    bvy = body_velocity[1] + omega * (tx - cx)
    robot_in = robot_velocity[0] * nx + robot_velocity[1] * ny
    body_in = -(bvx * nx + bvy * ny)
    return robot_in > body_in
