"""``zhang2022-uuv2d-v1``: the thesis's UUV law among shape-changing obstacles, sonar only.

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 4, §4.3, eqs. (4.11)-(4.13), Figs. 4.5-4.6 (originally: Y. Zhang and
J. Zhang, "A Navigation Algorithm for UUVs to Avoid Shape Changeable Obstacles", ICCAE 2022).

The law switches between two strategies (Fig. 4.6):

* **Target approaching** (mode ``"M1"``): straight to E at the largest speed the vehicle allows
  in that direction (V_max / max(|cos|, |sin|), (4.4)-(4.7)), slowing only to stop on E.
* **Obstacle avoiding** (mode ``"M2"``) while d_imin(t) <= L: r_imin(t) from the AMAPS grid
  (:class:`~uvnav.prediction.amaps.AmapsGrid`, the centre of the nearest square whose count passes
  the threshold); the direction tag from the line to E rotated toward the obstacle's mass centre;
  the forecast circle O_t at r_imin with radius R_i(t) (4.11), the mean displacement of r_imin over
  the last count(t) decisions, count(t) from (4.12); the two tangent points p+ and p- from the
  vehicle; and c(t+1) = p+/- (4.13).

How the text is read (docs/thesis-notes.md, Chapter 4, gives the reasons at more length):

1. *Tag and tangent (4.13).*  '+' when the line vehicle->E must turn counter-clockwise by
   [0, pi/2) to meet the mass centre, '-' for (-pi/2, 0) (the text says "the mass centre of the
   vehicle"; the obstacle's is meant).  Taken literally, (4.13) sends '+' to p+, the
   counter-clockwise tangent point — i.e. toward the side the mass centre lies on, through the
   body.  The tag is meant to choose the way round: the vehicle passes r_imin on the side *away*
   from the mass centre ('+' -> the clockwise tangent point, '-' -> the counter-clockwise one).
   Mass centres behind the vehicle (|angle| >= pi/2) take the tag of the angle's sign.  The tag is
   fixed when count(t) leaves 0 and kept while count(t) > 0 ("the decision made by last step"),
   also when r_imin moves to another obstacle: re-drawing it there (this law's first reading)
   made the vehicle turn back between two bodies whose nearest points alternated, and a moving
   body ran into it (6 of 100 ``random-ch4-hard`` scenes; all 100 succeed with the kept tag).
2. *Forecast radius.*  R_i(t) of (4.11) is how far r_imin moved per decision (deformation plus the
   sliding of the nearest point).  A circle of that radius would let the vehicle's *centre* graze
   r_imin, so the circle used is rho = min(R_i, ``radius_cap``) + r_vehicle + ``safety_margin``.
   With count(t) = 1 the one displacement from the previous decision is used; history is kept
   for at most ``history`` decisions (bounded memory).
3. *c(t+1) = p.*  The tangent point is the next waypoint; the vehicle heads for it at the largest
   speed its limits allow and re-plans at every decision (arriving exactly at p would make the
   vehicle stop whenever it is on the circle, where the tangent length is 0).  Inside the circle
   (no tangent) it heads along the limiting direction, the circle's tangent at the vehicle on the
   passing side, tilted outward in proportion to the penetration.
3b. *Which circle.*  A tangent to the circle at r_imin only keeps clear of r_imin; where the
   boundary beyond r_imin bends toward the vehicle (a lobe that grows toward it) the tangent line
   runs into it (measured with the literal rule: 199 [ev:ch4-notes.literal_success] of 200
   random scenes succeed, the one collision is seed 61).  With ``outer_tangent`` (default) the
   vehicle steers along the outermost passing-side tangent over the forecast circles (same
   radius) of every covered AMAPS square within L in front of it on the passing side — the
   tangent to the forecast-dilated visible boundary, as the Ch. 2 law does (its note 3).
   ``outer_tangent=False`` is the literal rule.
4. *Switching back.*  "When the vehicle is away from the obstacle" the law returns to target
   approaching: here, when d_imin > L, or when E lies more than ``leave_angle`` (90 degrees plus
   a little) from the direction of r_imin (heading for E moves away from the nearest point), or
   when the straight run of ``2 L`` toward E clears every covered AMAPS square by r_vehicle +
   margin.  With "d_imin > L" alone, following a boundary at clearance below L would circle a
   static obstacle for ever.
5. *Fig. 4.2(b).*  Openings between returns narrower than the vehicle plus ``mouth_margin`` on
   each side are closed before the grid update (:func:`~uvnav.sensors.sonar2d.
   close_narrow_openings`): the inner space behind a narrow entry is marked unsafe and never
   looks free.
6. *d_imin(t).*  The smaller of the current sweep's d_imin and the distance to r_imin from the
   grid (the grid remembers parts the viewing cone no longer sees).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from uvnav.controllers.base import (
    ControllerInfo,
    check_params,
    register,
)
from uvnav.dynamics.holonomic import HolonomicCommand, HolonomicSpec, velocity_toward
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.polygons import points_to_segment
from uvnav.geometry.tangents import circle_tangents
from uvnav.prediction.amaps import AmapsGrid, law_grid
from uvnav.sensors.sonar2d import SonarObservation, close_narrow_openings


@runtime_checkable
class Uuv2dController(Protocol):
    """A navigation law for the planar UUV of Chapter 4 (sonar observations, velocity commands)."""

    name: ClassVar[str]
    oracle: bool

    def reset(self, spec: HolonomicSpec, goal: np.ndarray, rng: np.random.Generator) -> None: ...

    def act(self, obs: SonarObservation) -> HolonomicCommand: ...

    @property
    def mode(self) -> str: ...


@dataclass(frozen=True)
class Zhang2022Params:
    """Parameters of ``zhang2022-uuv2d-v1``.

    Attributes:
        switch_distance: L, avoidance starts when d_imin <= L [m].
        cell: AMAPS square side [m].
        decay: AMAPS forgetting per sweep.
        threshold: AMAPS count for a square to be covered.
        free_weight: AMAPS count removed from a square seen free.
        hit_depth: AMAPS depth marked behind a return [m].
        grid_margin: the grid covers the start-goal box grown by this much [m].
        safety_margin: added to the forecast radius besides the vehicle's radius [m].
        radius_cap: largest R_i(t) used [m] (a jump of r_imin between obstacles is not motion).
        history: most past r_imin kept for (4.11).
        mouth_margin: openings narrower than 2 (r_vehicle + mouth_margin) are closed [m].
        clear_factor: the straight run toward E checked for leaving avoidance is this times L.
        leave_angle: avoidance also ends while E lies more than this [rad] from the direction
            of r_imin (heading for E then moves away from it).
        outer_tangent: steer along the outermost passing-side tangent over the forecast circles
            of every covered square within L in front (True), or r_imin's only (False: the
            literal (4.13)).
    """

    switch_distance: float = 1.5
    cell: float = 0.05
    decay: float = 0.99
    threshold: float = 0.5
    free_weight: float = 0.35
    hit_depth: float = 0.1
    grid_margin: float = 4.0
    safety_margin: float = 0.2
    radius_cap: float = 0.6
    history: int = 64
    mouth_margin: float = 0.1
    clear_factor: float = 2.0
    leave_angle: float = 0.5 * math.pi + 0.15
    outer_tangent: bool = True

    def __post_init__(self) -> None:
        check_params(
            self,
            positive=(
                "switch_distance",
                "cell",
                "decay",
                "threshold",
                "history",
                "clear_factor",
                "leave_angle",
            ),
            non_negative=(
                "free_weight",
                "hit_depth",
                "grid_margin",
                "safety_margin",
                "radius_cap",
                "mouth_margin",
            ),
        )
        law_grid(self)  # the grid's settings, checked now rather than at the first decision


@dataclass(frozen=True)
class _Near:
    """The covered squares around the vehicle from one :meth:`AmapsGrid.covered` scan (row-major
    order); :meth:`within` gives exactly what a scan of a smaller radius would."""

    centres: FloatArray
    labels: np.ndarray
    distances: FloatArray
    #: the radius [m] of the scan
    radius: float

    def within(self, radius: float) -> tuple[FloatArray, np.ndarray]:
        """Centres and labels within ``radius`` [m] (row-major, as a scan of that radius)."""
        if radius >= self.radius:  # everything scanned is within it
            return self.centres, self.labels
        keep = self.distances <= radius
        return self.centres[keep], self.labels[keep]

    def nearest(self, radius: float) -> tuple[float, FloatArray | None, int]:
        """:meth:`AmapsGrid.nearest` within ``radius`` [m]: the first nearest square overall is
        the first nearest of those within ``radius`` whenever it lies within it."""
        if len(self.distances) == 0:
            return math.inf, None, -1
        j = int(np.argmin(self.distances))
        if not self.distances[j] <= radius:
            return math.inf, None, -1
        return float(self.distances[j]), self.centres[j], int(self.labels[j])


@dataclass
class Decision:
    """What the law computed at one decision (for figures and tests)."""

    time: float
    mode: str
    d_min: float
    r_min: FloatArray | None = None
    label: int = -1
    tag: int = 0
    count: int = 0
    radius: float = 0.0
    tangent_points: FloatArray | None = None
    waypoint: FloatArray | None = None
    extra: dict[str, Any] = field(default_factory=dict)


class Zhang2022Uuv2dController:
    """The switching law of §4.3 on an AMAPS grid (see the module docstring)."""

    name: ClassVar[str] = "zhang2022-uuv2d-v1"

    def __init__(self, params: Zhang2022Params | None = None) -> None:
        self.params = params or Zhang2022Params()
        self.oracle = False
        self._spec = HolonomicSpec(1.0, 1.0)
        self._goal = np.zeros(2)
        self._mode = "M1"
        self.grid: AmapsGrid | None = None
        self._count = 0
        self._tag = 0
        self._label = -1
        self._history: deque[FloatArray] = deque(maxlen=self.params.history + 1)
        # |r_imin(k) - r_imin(k-1)| of the kept history, one fewer than the points (for (4.11))
        self._steps: deque[float] = deque(maxlen=self.params.history)
        self.last: Decision | None = None

    @property
    def mode(self) -> str:
        return self._mode

    def reset(self, spec: HolonomicSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        self._spec = spec
        self._goal = np.asarray(goal, dtype=float)
        self._mode = "M1"
        self.grid = None
        self._count = 0
        self._tag = 0
        self._label = -1
        self._history.clear()
        self._steps.clear()
        self.last = None

    # ----------------------------------------------------------------------------- pieces
    def _grid_for(self, position: FloatArray) -> AmapsGrid:
        if self.grid is None:
            p = self.params
            lo = np.minimum(position, self._goal)
            hi = np.maximum(position, self._goal)
            self.grid = AmapsGrid.covering(lo, hi, law_grid(p), margin=p.grid_margin)
        return self.grid

    @staticmethod
    def direction_tag(position: FloatArray, goal: FloatArray, centre: FloatArray) -> int:
        """+1 when the line vehicle->E turns counter-clockwise to meet the mass centre, else -1."""
        to_goal = math.atan2(goal[1] - position[1], goal[0] - position[0])
        to_centre = math.atan2(centre[1] - position[1], centre[0] - position[0])
        return 1 if wrap_scalar(to_centre - to_goal) >= 0.0 else -1

    def forecast_radius(self) -> float:
        """R_i(t) of (4.11) over the last count(t) displacements of r_imin [m] (uncapped)."""
        n = min(self._count, len(self._steps))
        if n <= 0:
            return 0.0
        steps = list(self._steps)
        return math.fsum(steps[len(steps) - n :]) / n

    def _remember(self, r_min: FloatArray) -> None:
        """Append r_imin to the history and its displacement from the last one to the steps."""
        point = np.array(r_min, dtype=float)
        if self._history:
            last = self._history[-1]
            self._steps.append(math.hypot(float(point[0] - last[0]), float(point[1] - last[1])))
        self._history.append(point)

    def _query_radius(self) -> float:
        """The one window radius [m] of a decision's AMAPS scan: it holds the squares (4.12)
        needs (L + 2 cells), the clear-path check (2 L + clearance) and the outer tangent (L)."""
        p = self.params
        clear = p.clear_factor * p.switch_distance + self._spec.radius + p.safety_margin + p.cell
        return max(p.switch_distance + 2.0 * p.cell, clear, p.switch_distance)

    def _path_clear(self, position: FloatArray, near: _Near, clearance: float) -> bool:
        px, py = float(position[0]), float(position[1])
        gx, gy = float(self._goal[0]) - px, float(self._goal[1]) - py
        dist = math.hypot(gx, gy)
        if dist < 1e-9:
            return True
        run = min(dist, self.params.clear_factor * self.params.switch_distance)
        centres, _ = near.within(run + clearance)
        if len(centres) == 0:
            return True
        end = (px + gx / dist * run, py + gy / dist * run)
        return bool(points_to_segment(centres, (px, py), end).min() > clearance)

    def _receding(self, position: FloatArray, r_min: FloatArray) -> bool:
        """True when E lies more than ``leave_angle`` from the direction of r_imin: heading for E
        then moves away from the nearest covered square."""
        px, py = float(position[0]), float(position[1])
        to_goal = math.atan2(float(self._goal[1]) - py, float(self._goal[0]) - px)
        to_near = math.atan2(float(r_min[1]) - py, float(r_min[0]) - px)
        return abs(wrap_scalar(to_goal - to_near)) > self.params.leave_angle

    def _approach(self, obs: SonarObservation) -> HolonomicCommand:
        gx = float(self._goal[0]) - float(obs.position[0])
        gy = float(self._goal[1]) - float(obs.position[1])
        dist = math.hypot(gx, gy)
        if dist < 1e-12:
            return HolonomicCommand(0.0, 0.0)
        return velocity_toward(
            math.atan2(gy, gx),
            dist / obs.period,
            self._spec,
            obs.heading,
            obs.period,
        )

    # -------------------------------------------------------------------------------- act
    def act(self, obs: SonarObservation) -> HolonomicCommand:
        p = self.params
        pos = np.asarray(obs.position, dtype=float)
        grid = self._grid_for(pos)
        s = obs.sonar
        width = 2.0 * (self._spec.radius + p.mouth_margin)
        ranges, ids = close_narrow_openings(s.origin, s.angles, s.ranges, s.hit_ids, width)
        grid.update(s.origin, s.angles, ranges, ids)
        # one window scan answers every grid question of this decision
        reach = self._query_radius()
        near = _Near(*grid.covered(pos, reach), reach)
        # only a square within L matters to (4.12); a little more keeps d_grid exact near L
        d_grid, r_min, label = near.nearest(p.switch_distance + 2.0 * p.cell)
        d_sonar = float(s.d_min.min()) if len(s.d_min) else math.inf
        d_min = min(d_grid, d_sonar)
        # (4.12)
        if d_min <= p.switch_distance and r_min is not None:
            self._count += 1
        else:
            self._count = 0
            self._history.clear()
            self._steps.clear()
        if self._count == 0 or r_min is None:
            self._mode = "M1"
            self.last = Decision(obs.time, "M1", d_min)
            return self._approach(obs)
        self._remember(r_min)
        centres = s.centres
        centre = centres[label] if 0 <= label < len(centres) else r_min
        if self._count == 1 or self._tag == 0:
            self._tag = self.direction_tag(pos, self._goal, centre)
        self._label = label
        clearance = self._spec.radius + p.safety_margin
        r_i = self.forecast_radius()
        rho = min(r_i, p.radius_cap) + clearance
        decision = Decision(
            obs.time, "M2", d_min, r_min, label, self._tag, self._count, rho, extra={"R_i": r_i}
        )
        self.last = decision
        if self._receding(pos, r_min) or self._path_clear(pos, near, clearance + p.cell):
            self._mode = "M1"
            decision.mode = "M1"
            return self._approach(obs)
        self._mode = "M2"
        tan = circle_tangents(pos, r_min, rho)
        decision.tangent_points = tan.points
        # '+' passes r_imin on the clockwise side (points[1]); '-' on the counter-clockwise side
        j = 1 if self._tag > 0 else 0
        if tan.inside:
            d = float(np.hypot(*(pos - r_min)))
            out = math.atan2(pos[1] - r_min[1], pos[0] - r_min[0])
            direction = out + self._tag * 0.5 * math.pi * min(d / rho, 1.0)
            decision.waypoint = pos + self._spec.v_max * obs.period * np.array(
                [math.cos(direction), math.sin(direction)]
            )
        else:
            decision.waypoint = tan.points[j]
            direction = float(tan.angles[j])
            if p.outer_tangent:
                direction = self._outermost(pos, r_min, rho, direction, near)
                if direction != float(tan.angles[j]):
                    decision.waypoint = pos + tan.length * np.array(
                        [math.cos(direction), math.sin(direction)]
                    )
                    decision.extra["outer"] = True
        return velocity_toward(direction, math.inf, self._spec, obs.heading, obs.period)

    def _outermost(
        self, pos: FloatArray, r_min: FloatArray, rho: float, direction: float, near: _Near
    ) -> float:
        """The passing-side tangent direction [rad] that clears the forecast circles (radius
        ``rho``) of every covered square within L in front of the vehicle on the passing side,
        not only r_imin's (reading 3b of the module docstring)."""
        centres, dist = near.centres, near.distances  # distances from pos (the scan's)
        if self.params.switch_distance < near.radius:
            keep = dist <= self.params.switch_distance
            centres, dist = centres[keep], dist[keep]
        if len(dist) == 0:
            return direction
        px, py = float(pos[0]), float(pos[1])
        base_r = math.atan2(float(r_min[1]) - py, float(r_min[0]) - px)
        ang = np.arctan2(centres[:, 1] - py, centres[:, 0] - px) - base_r
        ang = np.pi - np.mod(np.pi - ang, 2.0 * np.pi)
        front = (np.abs(ang) <= 0.5 * np.pi) & (dist > rho)
        if not front.any():
            return direction
        gamma = np.arcsin(rho / dist[front])
        current = wrap_scalar(direction - base_r)
        if self._tag > 0:  # clockwise side: the most clockwise tangent
            extreme = min(float(np.min(ang[front] - gamma)), current)
        else:
            extreme = max(float(np.max(ang[front] + gamma)), current)
        return base_r + max(-math.pi, min(math.pi, extreme))


register(
    ControllerInfo(
        name=Zhang2022Uuv2dController.name,
        factory=Zhang2022Uuv2dController,
        params_type=Zhang2022Params,
        summary="thesis Ch. 4: AMAPS nearest square, forecast circle (4.11)-(4.12), tangent "
        "waypoints (4.13)",
        reference="Zhang & Zhang, ICCAE 2022; thesis Ch. 4 §4.3",
        vehicle="uuv2d",
        sensing="sonar-fan",
    )
)
