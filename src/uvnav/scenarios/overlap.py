"""When two moving bodies of a 2D scene first interpenetrate (a property of the scene's world,
not of any law: the robot is left out).

Used to measure a generator's family (``mutual_avoidance`` in
:func:`uvnav.scenarios.generators.random_ch2_scenario`) and in its tests.  Bodies are advanced by
:class:`~uvnav.obstacles.ObstacleBatch` exactly as in an episode; at every step the pairs whose
bounding discs overlap are checked exactly with shapely (polygons as given; a disc as two discs,
by centre distance).  Interpenetration is an overlap deeper than ``tol`` [m] of the bounding
discs and a shared area above ``tol``² [m²] of the shapes.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from uvnav.obstacles import Body, DiscBody, ObstacleBatch
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.schema import Scenario


def _shape(body: Body, position: np.ndarray, heading: float) -> shapely.Polygon:
    local = np.asarray(body.outline(), dtype=float)
    c, s = math.cos(heading), math.sin(heading)
    world = local @ np.array([[c, s], [-s, c]]) + position
    return shapely.Polygon(world)


def first_interpenetration(
    scenario: Scenario, seed: int, horizon: float = 30.0, tol: float = 1e-3
) -> float | None:
    """The first time [s] within ``horizon`` [s] at which two of ``scenario``'s bodies overlap
    by more than ``tol`` [m] (``None``: never).  The episode seed ``seed`` draws the bodies'
    motions, as in an episode of that seed."""
    setup = build_episode(scenario, seed)
    bodies = [ob.body for ob in setup.obstacles]
    radii = np.array([b.bounding_radius for b in bodies])
    batch = ObstacleBatch(setup.obstacles)
    dt = float(setup.dt)
    steps = round(horizon / dt)
    iu, ju = np.triu_indices(len(bodies), k=1)
    for k in range(steps + 1):
        pos, head = batch.positions, batch.headings
        near = np.hypot(*(pos[iu] - pos[ju]).T) < radii[iu] + radii[ju] - tol
        for i, j in zip(iu[near], ju[near], strict=True):
            if _overlap_deep(bodies, pos, head, int(i), int(j), tol):
                return k * dt
        if k < steps:
            batch.step(k * dt, dt)
    return None


def _overlap_deep(
    bodies: list[Body], pos: np.ndarray, head: np.ndarray, i: int, j: int, tol: float
) -> bool:
    a, b = bodies[i], bodies[j]
    if isinstance(a, DiscBody) and isinstance(b, DiscBody):
        return float(np.hypot(*(pos[i] - pos[j]))) < a.radius + b.radius - tol
    area = _shape(a, pos[i], head[i]).intersection(_shape(b, pos[j], head[j])).area
    return bool(area > tol * tol)
