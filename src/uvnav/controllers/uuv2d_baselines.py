"""Baselines for Chapter 4 on the same sonar sensing: adapters around the existing unicycle laws.

* ``apf-uuv2d-v1`` — ``apf-v1`` (Khatib's potential field with wall-following escape,
  :mod:`uvnav.controllers.apf`) fed with the *current sweep only*: one
  :class:`~uvnav.sensors.ObstacleReading` per obstacle the sonar sees, with distance d_imin and
  nearest point r_imin from the visible returns (no memory: what the cone no longer sees is gone).
* ``zhang2019-uuv2d-v1`` — the thesis's Ch. 2 law ``zhang2019-v1``
  (:mod:`uvnav.controllers.zhang2019`) fed with the *AMAPS-derived* obstacles: the same grid as
  ``zhang2022-uuv2d-v1`` (same update, same narrow-opening closing), r_imin the nearest covered
  square, and for each obstacle an outline built from its covered squares (per 5-degree sector
  around the known mass centre, the farthest covered square: a star polygon containing every
  square seen).  Obstacle velocities are unknown to a sonar and set to 0.

Neither existing law is changed.  The adapter gives it a
:class:`~uvnav.dynamics.UnicycleSpec` with the UUV's V_max and U_max and turns its (V, u) command
into a velocity along theta + u T (T the decision period): |u| <= U_max keeps the turn bound (4.6)
and V <= V_max keeps the box (4.4)-(4.5) in every direction.  A turn on the spot (V = 0, u != 0)
becomes a creep at 0.1 % of V_max along the new direction, since the UUV's orientation is that of
its velocity (:mod:`uvnav.dynamics.holonomic`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from uvnav.controllers.apf import ApfController, ApfParams
from uvnav.controllers.base import (
    ControllerInfo,
    UnicycleController,
    build_params,
    check_params,
    register,
)
from uvnav.controllers.zhang2019 import Zhang2019Controller, Zhang2019Params
from uvnav.dynamics.holonomic import HolonomicCommand, HolonomicSpec
from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.geometry.angles import FloatArray
from uvnav.prediction.amaps import AmapsGrid, law_grid
from uvnav.sensors.observation import Observation, ObstacleReading
from uvnav.sensors.sonar2d import SonarObservation, close_narrow_openings

_SECTORS = 72
#: fraction of V_max used to turn on the spot (the orientation follows the velocity)
_CREEP = 1e-3


def reading_from_points(
    obstacle_id: int,
    position: FloatArray,
    nearest: FloatArray,
    distance: float,
    centre: FloatArray,
    points: FloatArray,
    *,
    outline: bool,
) -> ObstacleReading:
    """An :class:`ObstacleReading` from sensed boundary ``points`` (N, 2) [m] of one obstacle.

    With ``outline``, the outline is the star polygon of the farthest point per 5-degree sector
    around ``centre`` (a small square around ``nearest`` when fewer than three sectors are seen).
    """
    c = np.asarray(centre, dtype=float)
    rel = np.asarray(points, dtype=float) - c
    rad = np.hypot(rel[:, 0], rel[:, 1]) if len(rel) else np.zeros(0)
    bound = float(max(rad.max() if len(rad) else 0.0, np.hypot(*(nearest - c)))) + 1e-6
    poly = np.zeros((0, 2))
    if outline:
        ang = np.arctan2(rel[:, 1], rel[:, 0])
        sector = np.floor((ang + np.pi) / (2 * np.pi) * _SECTORS).astype(int) % _SECTORS
        far = np.full(_SECTORS, -1.0)
        np.maximum.at(far, sector, rad)
        keep = np.flatnonzero(far > 0)
        if len(keep) >= 3:
            a = (keep + 0.5) / _SECTORS * 2 * np.pi - np.pi
            poly = c + far[keep, None] * np.stack([np.cos(a), np.sin(a)], axis=-1)
        else:
            h = 0.05
            poly = np.asarray(nearest) + np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
            c = np.asarray(nearest, dtype=float)
    return ObstacleReading(
        obstacle_id=int(obstacle_id),
        distance=float(distance),
        nearest_point=np.asarray(nearest, dtype=float),
        centre=c,
        velocity=np.zeros(2),
        angular_velocity=0.0,
        outline=poly,
        radius=0.0,
        bounding_radius=bound,
        velocity_source="estimated",
    )


class _UnicycleOnUuv:
    """Runs a unicycle law on the UUV: builds its observation, converts its command."""

    name: ClassVar[str]

    def __init__(self, law: UnicycleController) -> None:
        self.law = law
        self.oracle = False
        self._spec = HolonomicSpec(1.0, 1.0)
        self._goal = np.zeros(2)

    @property
    def mode(self) -> str:
        return self.law.mode

    def reset(self, spec: HolonomicSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        self._spec = spec
        self._goal = np.asarray(goal, dtype=float)
        uspec = UnicycleSpec(v_max=spec.v_max, u_max=spec.u_max, radius=spec.radius)
        self.law.reset(uspec, self._goal, rng)
        self._reset_adapter()

    def _reset_adapter(self) -> None:
        """Per-episode state of the adapter (none by default)."""

    def readings(self, obs: SonarObservation) -> tuple[ObstacleReading, ...]:
        raise NotImplementedError

    def act(self, obs: SonarObservation) -> HolonomicCommand:
        readings = tuple(sorted(self.readings(obs), key=lambda r: r.distance))
        uobs = Observation(
            time=obs.time,
            pose=np.asarray(obs.pose, dtype=float),
            speed=float(np.hypot(*obs.velocity)),
            goal=np.asarray(obs.goal, dtype=float),
            obstacles=readings,
        )
        cmd = self.law.act(uobs)  # type: ignore[attr-defined]
        v = min(max(float(cmd.v), 0.0), self._spec.v_max) if math.isfinite(cmd.v) else 0.0
        u = float(cmd.u) if math.isfinite(cmd.u) else 0.0
        u = max(-self._spec.u_max, min(self._spec.u_max, u))
        ang = obs.heading + u * obs.period
        if v < _CREEP * self._spec.v_max and u != 0.0:
            # a unicycle turning on the spot: the UUV's orientation follows its velocity, so it
            # creeps along the new direction to turn
            v = _CREEP * self._spec.v_max
        return HolonomicCommand(v * math.cos(ang), v * math.sin(ang))


class ApfUuv2dController(_UnicycleOnUuv):
    """``apf-v1`` on the current sonar sweep (no memory)."""

    name: ClassVar[str] = "apf-uuv2d-v1"

    def __init__(self, params: ApfParams | None = None) -> None:
        super().__init__(ApfController(params))

    def readings(self, obs: SonarObservation) -> tuple[ObstacleReading, ...]:
        s = obs.sonar
        pts = s.points
        out = []
        for j, i in enumerate(s.ids):
            centre = s.centres[i] if i < len(s.centres) else s.r_min[j]
            mine = pts[s.hit_ids == i]
            out.append(
                reading_from_points(
                    int(i), obs.position, s.r_min[j], float(s.d_min[j]), centre, mine, outline=False
                )
            )
        return tuple(out)


@dataclass(frozen=True)
class Zhang2019Uuv2dParams:
    """``zhang2019-v1`` parameters plus the AMAPS grid's (same meaning as in
    :class:`~uvnav.controllers.zhang2022_uuv2d.Zhang2022Params`)."""

    law: dict[str, Any] | None = None
    cell: float = 0.05
    decay: float = 0.99
    threshold: float = 0.5
    free_weight: float = 0.35
    hit_depth: float = 0.1
    grid_margin: float = 4.0
    mouth_margin: float = 0.1

    def __post_init__(self) -> None:
        """Every check at construction (one line each), none at the first decision: the inner
        law's parameters, the grid's (:class:`AmapsConfig`) and the margins [m]."""
        build_params(Zhang2019Params, dict(self.law or {}))
        law_grid(self)
        check_params(self, non_negative=("mouth_margin",))


class Zhang2019Uuv2dController(_UnicycleOnUuv):
    """``zhang2019-v1`` on AMAPS-derived obstacles."""

    name: ClassVar[str] = "zhang2019-uuv2d-v1"

    def __init__(self, params: Zhang2019Uuv2dParams | None = None) -> None:
        self.params = params or Zhang2019Uuv2dParams()
        super().__init__(Zhang2019Controller(Zhang2019Params(**(self.params.law or {}))))
        self.grid: AmapsGrid | None = None

    def _reset_adapter(self) -> None:
        self.grid = None

    def readings(self, obs: SonarObservation) -> tuple[ObstacleReading, ...]:
        p = self.params
        pos = np.asarray(obs.position, dtype=float)
        if self.grid is None:
            lo, hi = np.minimum(pos, self._goal), np.maximum(pos, self._goal)
            self.grid = AmapsGrid.covering(lo, hi, law_grid(p), margin=p.grid_margin)
        s = obs.sonar
        width = 2.0 * (self._spec.radius + p.mouth_margin)
        ranges, ids = close_narrow_openings(s.origin, s.angles, s.ranges, s.hit_ids, width)
        self.grid.update(s.origin, s.angles, ranges, ids)
        centres, labels = self.grid.occupied(pos, s.max_range)
        out = []
        for lab in np.unique(labels):
            mine = centres[labels == lab]
            d = np.hypot(mine[:, 0] - pos[0], mine[:, 1] - pos[1])
            k = int(np.argmin(d))
            centre = s.centres[lab] if 0 <= lab < len(s.centres) else mine[k]
            out.append(
                reading_from_points(int(lab), pos, mine[k], float(d[k]), centre, mine, outline=True)
            )
        return tuple(out)


register(
    ControllerInfo(
        name=ApfUuv2dController.name,
        factory=ApfUuv2dController,
        params_type=ApfParams,
        summary="baseline: apf-v1 on the current sonar sweep",
        reference="Khatib 1986 (see apf-v1)",
        vehicle="uuv2d",
        sensing="sonar-fan",
    )
)
register(
    ControllerInfo(
        name=Zhang2019Uuv2dController.name,
        factory=Zhang2019Uuv2dController,
        params_type=Zhang2019Uuv2dParams,
        summary="baseline: zhang2019-v1 fed with AMAPS nearest squares and outlines",
        reference="thesis Ch. 2 law on the Ch. 4 AMAPS grid",
        vehicle="uuv2d",
        sensing="sonar-fan",
    )
)
