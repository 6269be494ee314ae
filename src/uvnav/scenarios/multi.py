"""Multi-robot scenarios: a pydantic schema beside the single-robot one, generators
and the builder for :func:`uvnav.sim.run.run_episode`.

A multi-robot scenario has a list of robots (each a single-robot ``robot`` block plus an optional
``controller`` and ``sensing`` of its own; omitted, the scenario's defaults apply) and the same
``obstacles`` as a single-robot scene.  Generators (``NAME:N``):

* ``antipodal:N`` — N robots evenly spaced on a circle, each going to the diametrically opposite
  point (the standard multi-agent swap benchmark of van den Berg et al., ISRR 2009).  Circle
  radius ``max(4, 1.2 N / (2 pi))`` m, so that neighbours start 1.2 m apart or more.
* ``crossing:N`` — two flows of N/2 robots crossing at right angles (a 4 x N/4 block going east,
  another going north), like two corridors meeting.
* ``thesis-ch2-multi:N`` — the thesis's Ch. 2 six-obstacle scene (Fig. 2.8) with N robots
  (N <= 8) starting on the square's corners and edge midpoints, each going to the opposite
  one, all with the same limits as the thesis's robot.

Errors are one line naming the source, the field and the problem
(:class:`~uvnav.scenarios.errors.ScenarioError`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import Field, ValidationError, model_validator

from uvnav.controllers.base import make_controller
from uvnav.scenarios.errors import FieldError, ScenarioError, from_validation_error
from uvnav.scenarios.limits import SceneModel, check_timing
from uvnav.scenarios.schema import (
    MOTION_TYPES,
    ControllerSpec,
    ObstacleSpec,
    RobotSpec,
    SensingSpec,
)
from uvnav.sim.seeding import world_rng
from uvnav.sim.setup import MultiSetup, RobotSetup


class MultiRobotSpec(RobotSpec):
    """One robot of a multi-robot scene: the single-robot block plus its own law and sensing."""

    name: str = Field("", description="label (plots, tables)")
    controller: ControllerSpec | None = Field(
        None, description="this robot's law; omitted = the scenario's controller"
    )
    sensing: SensingSpec | None = Field(
        None, description="this robot's sensing; omitted = the scenario's sensing"
    )


class MultiScenario(SceneModel):
    """A multi-robot scenario: robots, shared obstacles, timing, defaults."""

    name: str = Field(min_length=1, description="scenario name")
    description: str = Field("", description="what the scene is")
    dim: int = Field(2, ge=2, le=2, description="dimension of the world (2)")
    dt: float = Field(0.1, gt=0, description="integration step [s]")
    control_period: float = Field(0.1, gt=0, description="decision period [s], a multiple of dt")
    t_max: float = Field(60.0, gt=0, description="time limit [s]")
    goal_tolerance: float = Field(0.2, gt=0, description="arrival radius [m]")
    deadlock_window: float = Field(10.0, gt=0, description="window of the deadlock test [s]")
    deadlock_distance: float = Field(
        0.2, gt=0, description="moving less than this over the window is a deadlock [m]"
    )
    robots: list[MultiRobotSpec] = Field(min_length=1, description="the robots")
    sensing: SensingSpec = Field(default_factory=lambda: SensingSpec.model_validate({}))
    controller: ControllerSpec = Field(default_factory=lambda: ControllerSpec.model_validate({}))
    obstacles: list[ObstacleSpec] = Field(default_factory=list)

    @model_validator(mode="after")
    def _consistent(self) -> MultiScenario:
        check_timing(self.t_max, self.dt, self.control_period)
        starts = np.array([r.start for r in self.robots], dtype=float)
        goals = np.array([r.goal for r in self.robots], dtype=float)
        radii = np.array([r.radius for r in self.robots], dtype=float)
        for what, pts, tol in (("start", starts, 0.0), ("goal", goals, -1.0)):
            d = np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1))
            need = radii[:, None] + radii[None, :] if tol >= 0 else np.zeros_like(d)
            np.fill_diagonal(d, np.inf)
            bad = np.argwhere(d <= need) if tol >= 0 else np.argwhere(d <= 1e-9)
            if len(bad):
                i, j = (int(v) for v in bad[0])
                raise FieldError(
                    f"robots.{j}.{what}",
                    f"coincides with or overlaps robot {i}'s {what} at t=0",
                )
        return self

    def robot_controller(self, i: int) -> ControllerSpec:
        return self.robots[i].controller or self.controller

    def robot_sensing(self, i: int) -> SensingSpec:
        return self.robots[i].sensing or self.sensing


def build_multi(
    scenario: MultiScenario,
    seed: int,
    *,
    controller: str | None = None,
    params: dict[str, Any] | None = None,
) -> MultiSetup:
    """Instantiate ``scenario`` for one episode; ``controller`` (with ``params``) overrides every
    robot's law.  Obstacle j draws from ``world_rng(seed).spawn(n)[j]`` as in single-robot
    scenes."""
    children = world_rng(seed).spawn(len(scenario.obstacles))
    obstacles = [
        spec.to_obstacle(child, scenario.dt, j)
        for j, (spec, child) in enumerate(zip(scenario.obstacles, children, strict=True))
    ]
    robots = []
    for i, r in enumerate(scenario.robots):
        if controller is not None:
            ctrl = make_controller(controller, **(params or {}))
        else:
            cs = scenario.robot_controller(i)
            ctrl = make_controller(cs.name, **cs.params)
        robots.append(
            RobotSetup(
                spec=r.to_spec(),
                start=np.array([r.start[0], r.start[1], r.initial_heading()]),
                goal=np.asarray(r.goal, dtype=float),
                controller=ctrl,
                sensing=scenario.robot_sensing(i).to_config(),
                name=r.name or f"robot-{i}",
            )
        )
    return MultiSetup(
        robots=robots,
        obstacles=obstacles,
        dt=float(scenario.dt),
        control_period=float(scenario.control_period),
        t_max=float(scenario.t_max),
        goal_tolerance=float(scenario.goal_tolerance),
        deadlock_window=float(scenario.deadlock_window),
        deadlock_distance=float(scenario.deadlock_distance),
    )


# -------------------------------------------------------------------------------- generators

ROBOT = {"v_max": 0.7, "u_max": 1.4, "radius": 0.2}


def _robot(start: np.ndarray, goal: np.ndarray, name: str, **limits: float) -> dict[str, Any]:
    return {
        "name": name,
        "start": [round(float(start[0]), 6), round(float(start[1]), 6)],
        "goal": [round(float(goal[0]), 6), round(float(goal[1]), 6)],
        **{**ROBOT, **limits},
    }


def antipodal_scenario(n: int, *, controller: str = "zhang2019-v1") -> MultiScenario:
    """``antipodal:n``: n robots on a circle swapping to the opposite points (module docs)."""
    if not 2 <= n <= 256:
        raise ValueError(f"antipodal needs 2..256 robots (got {n})")
    radius = max(4.0, 1.2 * n / (2.0 * math.pi))
    ang = 2.0 * math.pi * np.arange(n) / n
    pts = radius * np.column_stack((np.cos(ang), np.sin(ang)))
    robots = [_robot(pts[i], -pts[i], f"robot-{i}") for i in range(n)]
    v_max = ROBOT["v_max"]
    data = {
        "name": f"antipodal-{n}",
        "description": f"{n} robots on a circle of radius {radius:.2f} m swap to the antipodal "
        "points (van den Berg et al., ISRR 2009).",
        "t_max": round(6.0 * 2.0 * radius / v_max, 1),
        "robots": robots,
        "sensing": {"range": 5.0},
        "controller": {"name": controller},
    }
    return multi_from_dict(data, f"antipodal:{n}")


def crossing_scenario(n: int, *, controller: str = "zhang2019-v1") -> MultiScenario:
    """``crossing:n``: two perpendicular flows of n/2 robots each (module docs)."""
    if n < 2 or n % 2:
        raise ValueError(f"crossing needs an even number of robots >= 2 (got {n})")
    half = n // 2
    rows = min(4, half)
    cols = math.ceil(half / rows)
    robots = []
    for k in range(half):
        r, c = divmod(k, cols)
        lane = (r - (rows - 1) / 2) * 1.0
        back = c * 1.2
        robots.append(
            _robot(np.array([-8.0 - back, lane]), np.array([8.0 - back, lane]), f"east-{k}")
        )
        robots.append(
            _robot(np.array([lane, -8.0 - back - 0.6]), np.array([lane, 8.0 - back]), f"north-{k}")
        )
    data = {
        "name": f"crossing-{n}",
        "description": f"two flows of {half} robots crossing at right angles at the origin.",
        "t_max": 90.0,
        "robots": robots,
        "controller": {"name": controller},
    }
    return multi_from_dict(data, f"crossing:{n}")


def thesis_ch2_multi_scenario(n: int, *, controller: str = "zhang2019-v1") -> MultiScenario:
    """``thesis-ch2-multi:n``: the Fig. 2.8 six-obstacle scene with n <= 8 robots (module
    docs)."""
    from uvnav.scenarios.loader import load_scenario

    if not 1 <= n <= 8:
        raise ValueError(f"thesis-ch2-multi takes 1..8 robots (got {n})")
    base = load_scenario("thesis-ch2-six-obstacles")
    spots = np.array(
        [[0, 0], [10, 10], [10, 0], [0, 10], [5, -1], [5, 11], [-1, 5], [11, 5]], dtype=float
    )
    opposite = np.array(
        [[10, 10], [0, 0], [0, 10], [10, 0], [5, 11], [5, -1], [11, 5], [-1, 5]], dtype=float
    )
    r = base.robot
    robots = [
        _robot(spots[i], opposite[i], f"robot-{i}", v_max=r.v_max, u_max=r.u_max, radius=r.radius)
        for i in range(n)
    ]
    data = {
        "name": f"thesis-ch2-multi-{n}",
        "description": "Thesis Fig. 2.8 scene (six moving non-convex obstacles) with "
        f"{n} robots crossing it to the opposite side.",
        "dt": base.dt,
        "control_period": base.control_period,
        "t_max": base.t_max,
        "goal_tolerance": base.goal_tolerance,
        "robots": robots,
        "sensing": base.sensing.model_dump(),
        "controller": {"name": controller},
        "obstacles": [o.model_dump(exclude_none=True) for o in base.obstacles],
    }
    return multi_from_dict(data, f"thesis-ch2-multi:{n}")


MULTI_GENERATORS = {
    "antipodal": antipodal_scenario,
    "crossing": crossing_scenario,
    "thesis-ch2-multi": thesis_ch2_multi_scenario,
}


def multi_from_dict(data: Any, source: str = "<dict>") -> MultiScenario:
    """Validate a mapping as a :class:`MultiScenario`.

    Raises:
        ScenarioError: one line naming ``source``, the field path and the problem.
    """
    if not isinstance(data, dict):
        raise ScenarioError(source, "<root>", "expected a mapping of multi-robot scenario fields")
    try:
        sc = MultiScenario.model_validate(data)
    except ValidationError as exc:
        raise from_validation_error(exc, source, tags=tuple(MOTION_TYPES)) from None
    sc._source = source
    return sc


def load_multi_scenario(name: str | Path) -> MultiScenario:
    """A generator spec ``NAME:N`` (``antipodal:16``) or a YAML file.

    Raises:
        ScenarioError: unknown generator, bad N, unreadable file or invalid content.
    """
    text = str(name)
    gen, sep, arg = text.partition(":")
    if sep and gen in MULTI_GENERATORS:
        try:
            n = int(arg)
        except ValueError:
            raise ScenarioError(
                text, "<generator>", f"N must be an integer (got {arg!r})"
            ) from None
        try:
            return MULTI_GENERATORS[gen](n)
        except ValueError as exc:
            raise ScenarioError(text, "<generator>", str(exc)) from None
    path = Path(text)
    if not path.is_file():
        known = ", ".join(f"{g}:N" for g in MULTI_GENERATORS)
        raise ScenarioError(text, "<name>", f"not a file nor a generator; generators: {known}")
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ScenarioError(text, "<yaml>", str(exc).replace("\n", " ")) from None
    return multi_from_dict(data, text)
