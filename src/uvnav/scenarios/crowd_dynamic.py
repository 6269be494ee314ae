"""A harder crowd than CrowdNav's test protocol, as a generator: ``crowd-dynamic:<seed>``.

CrowdNav's circle crossing (:mod:`uvnav.scenarios.crowdnav`) has five humans of one size and one
speed, each walking once to the point opposite its start and stopping there.  Crowd-navigation
work since evaluates in denser, livelier crowds (e.g. CrowdNav++: Liu et al., "Intention aware
robot crowd navigation with attention-based interaction graph", ICRA 2023: 20 humans of random
size and speed, goals that change at random times and on arrival, 5 m sensing).  This generator
draws such a crowd from ``np.random.default_rng(seed)`` (nothing else is random):

* **humans**: ``n_humans`` (20), each with a radius uniform in ``radius_range`` ([0.3, 0.5] m)
  and a preferred speed uniform in ``v_pref_range`` ([0.5, 1.5] m/s), drawn in that order per
  human; an ORCA pedestrian of one crowd (``orca_crowd`` motion, :mod:`uvnav.obstacles.crowd`:
  CrowdNav's ORCA parameters, deciding every ``time_step``), who avoids the others reciprocally
  and, with ``robot_visible``, the robot too;
* **start and first goal**: the start uniform in the arena's disc of radius ``arena_radius``
  (6 m), the first goal opposite it through the centre (``-start``, so most first legs cross
  the robot's path); redrawn while the start is within ``r + r_other + 0.2 m`` of another
  human's start, the goal of another's goal, or either within ``r + R + 1 m`` of the robot's
  start or goal.  (CrowdNav's circle crossing puts every start and goal on one circle: 20
  humans of up to 0.5 m do not fit on it apart, hence a disc.)  The crowd fills the arena from
  ``t = 0``;
* **goal changes**: each human changes its goal at random times, a Poisson process of mean
  interval ``goal_change_interval`` (8 s), and sets off to a new goal as soon as it arrives
  (its centre within its radius of its goal); every new goal is uniform in the arena's disc and
  at least ``MIN_LEG`` (2 m) from the goal before it.  Those goals and times are drawn with
  the scene (enough for the whole episode), so the scene is a fixed file like any other.  An
  arriving human is not removed and replaced by a new one elsewhere: it stays and walks on to
  its new goal, which keeps the crowd's size and density as a replacement would, without bodies
  that appear or vanish;
* **walls** (``walls``): two static walls along the robot's path at ``x = +-wall_half_width``
  (a corridor), every start and goal kept at least ``WALL_CLEARANCE`` (0.2 m) off them.  The
  humans' ORCA does not see the walls (RVO2 is given the humans only): their straight legs stay
  between the walls, their avoidance may push them against one;
* **robot**: from ``(0, -arena_radius)`` to ``(0, arena_radius)``, heading pi/2, at rest, radius
  ``robot_radius`` (0.3 m, also the goal tolerance), V_max ``v_pref`` (1 m/s); the law picks the
  vehicle (a holonomic law the holonomic robot, a unicycle law the unicycle, with
  ``accel_max`` / ``turn_accel_max`` when given); it sees the humans within ``sensing_range``
  (5 m; a large range shows every human);
* **time**: decisions of robot and crowd every ``time_step`` (0.25 s), integration every ``dt``
  (0.25 s), episodes of ``t_max`` (50 s).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field

from uvnav.scenarios.crowdnav import (
    CROWDNAV_ORCA_PARAMS,
    MAX_DRAWS,
    UNICYCLE_U_MAX,
    crossing_robot,
)
from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.params import typed_generator
from uvnav.scenarios.parse import scenario_from_dict
from uvnav.scenarios.schema import Scenario

NAME = "crowd-dynamic"
#: the crowd's default size
N_HUMANS = 20
#: the robot's default sensing range [m]
SENSING_RANGE = 5.0
#: a new goal is at least this far from the one before [m]
MIN_LEG = 2.0
#: starts and goals keep this gap to a wall [m]
WALL_CLEARANCE = 0.2
#: wall thickness [m]
WALL_THICKNESS = 0.3
#: the gap kept between two humans' starts (or goals), beyond their radii [m] (CrowdNav's)
DISCOMFORT = 0.2
#: the gap kept between a human's start (or goal) and the robot's, beyond their radii [m]
ROBOT_CLEARANCE = 1.0

_Human = dict[str, Any]


def _positive(description: str) -> Any:
    return Field(gt=0, allow_inf_nan=False, description=description)


def _inside(x: float, r: float, half_width: float | None) -> bool:
    """Whether a disc of radius ``r`` [m] centred at abscissa ``x`` keeps off the walls."""
    return half_width is None or abs(x) <= half_width - r - WALL_CLEARANCE


def _start_and_goal(
    rng: np.random.Generator,
    r: float,
    arena: float,
    robot_radius: float,
    taken: list[tuple[float, float, float, float, float]],
    half_width: float | None,
) -> tuple[float, float] | None:
    """A start uniform in the arena's disc (goal: its opposite) clear of the walls, of the
    ``taken`` humans' starts and goals (``(sx, sy, gx, gy, radius)``) and, by
    :data:`ROBOT_CLEARANCE`, of the robot's start ``(0, -arena)`` and goal ``(0, arena)``
    (the goal too, by symmetry); ``None`` after :data:`MAX_DRAWS` draws."""
    robot_gap = r + robot_radius + ROBOT_CLEARANCE
    for _ in range(MAX_DRAWS):
        rad = arena * math.sqrt(rng.random())
        ang = rng.uniform(0.0, 2.0 * math.pi)
        px, py = rad * math.cos(ang), rad * math.sin(ang)
        if not _inside(px, r, half_width):
            continue
        if min(math.hypot(px, py - arena), math.hypot(px, py + arena)) < robot_gap:
            continue
        if not any(
            math.hypot(px - a[0], py - a[1]) < r + a[4] + DISCOMFORT
            or math.hypot(-px - a[2], -py - a[3]) < r + a[4] + DISCOMFORT
            for a in taken
        ):
            return px, py
    return None


def _later_goals(
    rng: np.random.Generator,
    first: tuple[float, float],
    count: int,
    r: float,
    arena: float,
    half_width: float | None,
) -> list[list[float]]:
    """``count`` goals uniform in the arena's disc (off the walls), each at least
    :data:`MIN_LEG` from the one before."""
    goals: list[list[float]] = []
    prev = first
    while len(goals) < count:
        rad = arena * math.sqrt(rng.random())
        ang = rng.uniform(0.0, 2.0 * math.pi)
        gx, gy = rad * math.cos(ang), rad * math.sin(ang)
        if math.hypot(gx - prev[0], gy - prev[1]) >= MIN_LEG and _inside(gx, r, half_width):
            goals.append([gx, gy])
            prev = (gx, gy)
    return goals


def _change_times(rng: np.random.Generator, interval: float, t_max: float) -> list[float]:
    """The times of a Poisson process of mean ``interval`` [s] before ``t_max`` [s]."""
    times: list[float] = []
    t = float(rng.exponential(interval))
    while t < t_max:
        times.append(t)
        t += float(rng.exponential(interval))
    return times


def _humans(
    rng: np.random.Generator, n: int, radius_range: tuple[float, float],
    v_pref_range: tuple[float, float], arena: float, robot_radius: float,
    interval: float, t_max: float, half_width: float | None,
) -> list[_Human]:  # fmt: skip
    """Every human's radius, speed, start, goals and change times (module docstring).

    Raises:
        ValueError: a human cannot be placed in :data:`MAX_DRAWS` draws.
    """
    taken: list[tuple[float, float, float, float, float]] = []
    out: list[_Human] = []
    for i in range(n):
        r = float(rng.uniform(*radius_range))
        v = float(rng.uniform(*v_pref_range))
        start = _start_and_goal(rng, r, arena, robot_radius, taken, half_width)
        if start is None:
            raise ValueError(
                f"cannot place human {i + 1} of {n} apart from the others after {MAX_DRAWS} "
                "draws: too many humans for the arena (lower n_humans)"
            )
        px, py = start
        times = _change_times(rng, interval, t_max)
        # one goal per change, and one per arrival: a leg of MIN_LEG takes MIN_LEG / v or more
        count = len(times) + math.ceil(t_max * v / MIN_LEG) + 1
        later = _later_goals(rng, (-px, -py), count, r, arena, half_width)
        taken.append((px, py, -px, -py, r))
        out.append({"radius": r, "v_pref": v, "start": [px, py], "goal": [-px, -py],
                    "next_goals": later, "change_times": times})  # fmt: skip
    return out


def _walls(half_width: float, arena: float) -> list[dict[str, Any]]:
    """Two static walls along the y axis at ``x = +-half_width`` (their inner faces)."""
    h, t = arena + 2.0, WALL_THICKNESS
    body = {"polygon": [[-t / 2, -h], [t / 2, -h], [t / 2, h], [-t / 2, h]]}
    return [
        {"name": f"wall-{side}", "body": body,
         "start": {"position": [sign * (half_width + t / 2), 0.0]},
         "motion": {"type": "constant", "velocity": [0.0, 0.0]}}
        for side, sign in (("west", -1.0), ("east", 1.0))
    ]  # fmt: skip


@typed_generator(NAME)
def crowd_dynamic_scenario(
    seed: int,
    *,
    n_humans: Annotated[int, Field(ge=0, le=200, description="number of humans")] = N_HUMANS,
    radius_min: Annotated[float, _positive("smallest human radius [m]")] = 0.3,
    radius_max: Annotated[float, _positive("largest human radius [m]")] = 0.5,
    v_pref_min: Annotated[float, _positive("slowest preferred speed [m/s]")] = 0.5,
    v_pref_max: Annotated[float, _positive("fastest preferred speed [m/s]")] = 1.5,
    goal_change_interval: Annotated[
        float, _positive("mean time between a human's random goal changes [s]")
    ] = 8.0,
    arena_radius: Annotated[
        float, _positive("humans' circle and goal disc, the robot's start/goal distance [m]")
    ] = 6.0,
    robot_visible: Annotated[
        bool, Field(description="the humans see the robot and avoid it (ORCA)")
    ] = False,
    walls: Annotated[bool, Field(description="two static walls along the robot's path")] = False,
    wall_half_width: Annotated[
        float, _positive("distance from the robot's path to each wall [m]")
    ] = 5.0,
    sensing_range: Annotated[float, _positive("the robot sees humans within this [m]")] = (
        SENSING_RANGE
    ),
    dt: Annotated[float, _positive("integration step [s], a divisor of time_step")] = 0.25,
    time_step: Annotated[float, _positive("decision period of robot and crowd [s]")] = 0.25,
    t_max: Annotated[float, _positive("episode length [s]")] = 50.0,
    robot_radius: Annotated[
        float, _positive("robot disc radius, also the goal tolerance [m]")
    ] = 0.3,
    v_pref: Annotated[float, _positive("robot V_max [m/s]")] = 1.0,
    u_max: Annotated[float, _positive("U_max of the unicycle variant [rad/s]")] = UNICYCLE_U_MAX,
    kinematics: Annotated[
        Literal["turn-then-move", "arc"], Field(description="the unicycle variant's kinematics")
    ] = "turn-then-move",
    accel_max: Annotated[
        float | None,
        Field(gt=0, allow_inf_nan=False, description="largest speed change [m/s^2]"),
    ] = None,
    turn_accel_max: Annotated[
        float | None,
        Field(gt=0, allow_inf_nan=False, description="largest turn-rate change [rad/s^2]"),
    ] = None,
    controller: Annotated[str, Field(description="the scene's own law")] = "orca-holonomic-v1",
) -> Scenario:
    """Scene ``seed`` of the harder crowd (module docstring for every choice).

    Args:
        seed: the scene's number (``np.random.default_rng(seed)``), >= 0.
        n_humans, radius_min, radius_max, v_pref_min, v_pref_max: the crowd's size and the
            ranges its radii [m] and preferred speeds [m/s] are drawn from.
        goal_change_interval: mean time between a human's random goal changes [s].
        arena_radius: the humans' circle and goal disc, the robot's start/goal distance [m].
        robot_visible: the humans see the robot and avoid it (ORCA, reciprocally).
        walls, wall_half_width: two static walls at ``x = +-wall_half_width`` [m].
        sensing_range: the robot sees humans within this [m].
        dt, time_step, t_max: integration step, decision period, episode length [s].
        robot_radius, v_pref, u_max, kinematics, accel_max, turn_accel_max: the robot
            (:func:`uvnav.scenarios.crowdnav.crowdnav_scenario`'s).
        controller: the scene's own law (``orca-holonomic-v1``: with CrowdNav's robot ORCA).
    """
    where = f"{NAME}:{seed}"
    if seed < 0:
        raise ScenarioError(where, "seed", f"must be >= 0 (got {seed})")
    for lo, hi, name in ((radius_min, radius_max, "radius"), (v_pref_min, v_pref_max, "v_pref")):
        if lo > hi:
            raise ScenarioError(where, f"params.{name}_min", f"{lo:g} > {name}_max {hi:g}")
    half_width = wall_half_width if walls else None
    if half_width is not None and half_width <= robot_radius + WALL_CLEARANCE:
        raise ScenarioError(where, "params.wall_half_width", "leaves the robot no room")
    rng = np.random.default_rng(seed)
    try:
        humans = _humans(
            rng, n_humans, (radius_min, radius_max), (v_pref_min, v_pref_max), arena_radius,
            robot_radius, goal_change_interval, t_max, half_width,
        )  # fmt: skip
    except ValueError as exc:
        raise ScenarioError(where, "params.n_humans", str(exc)) from None
    obstacles: list[dict[str, Any]] = [
        {
            "name": f"human-{i}",
            "body": {"disc": h["radius"]},
            "start": {"position": h["start"], "heading": 0.0},
            "motion": {
                "type": "orca_crowd",
                "goal": h["goal"],
                "v_pref": h["v_pref"],
                "period": time_step,
                "sees_robot": bool(robot_visible),
                "next_goals": h["next_goals"],
                "change_times": h["change_times"],
                "arrival": h["radius"],
            },
        }
        for i, h in enumerate(humans)
    ]
    if half_width is not None:
        obstacles += _walls(half_width, arena_radius)
    params = dict(CROWDNAV_ORCA_PARAMS) if controller == "orca-holonomic-v1" else {}
    sees = "see" if robot_visible else "do not see"
    data: dict[str, Any] = {
        "name": f"{NAME}-{seed}",
        "description": (
            f"{n_humans} ORCA humans of random radius ({radius_min:g}-{radius_max:g} m) and "
            f"speed ({v_pref_min:g}-{v_pref_max:g} m/s) who change goals at random times (mean "
            f"{goal_change_interval:g} s) and on arrival, and {sees} the robot"
            f"{', between two walls' if walls else ''}; robot from (0, {-arena_radius:g}) to "
            f"(0, {arena_radius:g}), sensing {sensing_range:g} m."
        ),
        "dim": 2,
        "dt": dt,
        "control_period": time_step,
        "t_max": t_max,
        "goal_tolerance": robot_radius,
        "robot": crossing_robot(
            arena_radius, v_pref, u_max, robot_radius, kinematics, accel_max, turn_accel_max
        ),
        "sensing": {"range": sensing_range, "velocities": "known"},
        "obstacles": obstacles,
        "controller": {"name": controller, "params": params},
    }
    return scenario_from_dict(data, source=where)
