"""CrowdNav's test scenes as generators: ``crowdnav-circle:<case>`` and ``crowdnav-square:<case>``.

The crowd-navigation benchmark of Chen, Liu, Kreiss, Alahi, "Crowd-robot interaction: crowd-aware
robot navigation with attention-based deep reinforcement learning", ICRA 2019 (arXiv:1809.08835),
simulated by CrowdSim (https://github.com/vita-epfl/CrowdNav, studied for this module, not
copied).  Scene number ``case`` is CrowdNav's test case ``case``: the humans are drawn exactly as
CrowdSim draws them, from numpy's legacy global generator seeded ``1000 + case`` in the test
phase (``CrowdSim.reset``: ``np.random.seed(counter_offset[phase] + case_counter[phase])`` with
``counter_offset['test'] = case_capacity['val'] = 1000``), here a ``RandomState`` of that seed, with
the same calls in the same order.  So ``crowdnav-circle:0`` ... ``crowdnav-circle:499`` are the
500 cases of ``python test.py --policy orca`` (``test_size = 500``).

The set-up, with its source (``crowd_nav/configs/env.config`` unless said otherwise):

* humans: ``human_num = 5`` (``n_humans``), radius 0.3 m, ``v_pref`` 1 m/s (``human_v_pref``),
  policy ORCA, each an ``orca_crowd`` pedestrian of one crowd (:mod:`uvnav.obstacles.crowd`:
  CrowdNav's ORCA parameters, decision period = the time step);
* circle crossing (``CrowdSim.generate_circle_crossing_human``): angle uniform in [0, 2 pi), the
  start ``circle_radius`` (4 m) from the origin at that angle plus a noise uniform in
  ``[-v_pref/2, v_pref/2)`` on each axis, the goal the start's opposite ``-start``; a draw is
  redone while the start is within ``r_human + r_other + discomfort_dist`` (0.3 + 0.3 + 0.2 m) of
  another agent's start or goal (robot included);
* square crossing (``generate_square_crossing_human``): a side ``sign`` (+1 or -1, even odds),
  start uniform in ``[0, square_width/2) sign`` x ``[-square_width/2, square_width/2)``
  (``square_width`` 10 m), goal likewise on the other side; a start is redrawn while within the
  same distance of another agent's start, a goal while within it of another agent's goal;
* robot (``CrowdSim.reset``): from (0, -circle_radius) to (0, circle_radius), heading pi/2, at
  rest, radius 0.3 m, ``v_pref`` 1 m/s (here V_max), invisible to the humans (``visible =
  false``), seeing every human (``sensor = coordinates``: the sensing range here is 20 m);
* time (``[env]``): time step 0.25 s (the robot's decision period and the crowd's); the time
  limit 25 s acts as 24 s, because ``CrowdSim.step`` ends the episode as a timeout once
  ``global_time >= time_limit - 1``, before looking at the step: ``t_max = time_limit - 1``;
* success (``CrowdSim.step``): the robot's position after the step within its radius of the goal
  (``goal_tolerance`` = robot radius);
* collision: the robot's disc touching a human's (radius sum 0.6 m).  CrowdNav tests the segment
  the relative position would sweep over the step with the human's *previous* velocity; here
  the world judges the whole of every integration step ``dt`` (0.25 s by default) with the
  positions the robot and the humans actually pass through (:mod:`uvnav.sim.swept`);
* randomised attributes (``randomize_attributes = false``): off by default; when on, each human
  draws ``v_pref`` in [0.5, 1.5) and radius in [0.3, 0.5) first, as ``sample_random_attributes``.

The scene's own law is ``orca-holonomic-v1`` with the robot's ORCA of CrowdNav (``ORCA`` policy
with ``safety_space`` 0, ``crowd_nav/test.py``): time horizon 5 s, neighbour distance 10 m, at most
10 neighbours, reciprocal responsibility 0.5 (RVO2's own), and a combined radius 0.62 m (CrowdNav
adds 0.01 m to the robot's and to each human's radius: ``safety_margin`` 0.02 on the robot here).
The law picks the robot: a holonomic law drives the holonomic disc robot, a unicycle law the
unicycle (``u_max`` pi rad/s: CrowdNav's unicycle turns at most pi/4 per 0.25 s step), which moves
as CrowdNav's does (``kinematics: turn-then-move``: CrowdSim's ``ActionRot`` turns the robot by
the step's rotation, then moves it straight at its speed); ``kinematics=arc`` gives the thesis's
continuous turn instead.
"""

from __future__ import annotations

import math
from functools import partial
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field

from uvnav.controllers.orca import CROWDNAV_ORCA
from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.params import typed_generator
from uvnav.scenarios.parse import scenario_from_dict
from uvnav.scenarios.schema import Scenario

#: CrowdNav's ``env.config``
CIRCLE_RADIUS = 4.0  # [m]
SQUARE_WIDTH = 10.0  # [m]
N_HUMANS = 5
HUMAN_RADIUS = 0.3  # [m]
HUMAN_V_PREF = 1.0  # [m/s]
ROBOT_RADIUS = 0.3  # [m]
ROBOT_V_PREF = 1.0  # [m/s]
TIME_STEP = 0.25  # [s]
TIME_LIMIT = 25.0  # [s]
DISCOMFORT_DIST = 0.2  # [m]
#: seed offsets of the phases (``CrowdSim.reset``: ``counter_offset``)
PHASE_OFFSET: dict[str, int] = {"val": 0, "test": 1000, "train": 2000}
#: the robot's ORCA in CrowdNav (``crowd_sim/envs/policy/orca.py``, ``test.py``)
CROWDNAV_ORCA_PARAMS: dict[str, Any] = dict(CROWDNAV_ORCA)
#: the unicycle variant's U_max (CrowdNav's unicycle: rotations within +-pi/4 per 0.25 s step)
UNICYCLE_U_MAX = math.pi  # [rad/s]
SENSING_RANGE = 20.0  # [m]

_Agent = tuple[float, float, float, float, float]  # px, py, gx, gy, radius
#: draws per human before a scene is refused as unplaceable (CrowdSim redraws forever: 12 humans
#: at v_pref 0.5 on the 4 m circle never fit for some cases; a placeable scene takes far fewer)
MAX_DRAWS = 20_000


def crossing_robot(
    half: float,
    v_pref: float,
    u_max: float,
    radius: float,
    kinematics: str,
    accel_max: float | None,
    turn_accel_max: float | None,
) -> dict[str, Any]:
    """The ``robot`` section of a crossing scene: a unicycle from ``(0, -half)`` to ``(0, half)``
    [m], facing +y, at ``v_pref`` [m/s] and ``u_max`` [rad/s], of ``radius`` [m], with its
    kinematics and acceleration limits ([m/s^2], [rad/s^2]; ``None``: none)."""
    return {
        "model": "unicycle",
        "start": [0.0, -half],
        "heading": math.pi / 2,
        "goal": [0.0, half],
        "v_max": v_pref,
        "u_max": u_max,
        "radius": radius,
        "kinematics": kinematics,
        "accel_max": accel_max,
        "turn_accel_max": turn_accel_max,
    }


def _give_up(i: int, n: int) -> ValueError:
    return ValueError(
        f"cannot place human {i + 1} of {n} apart from the others after {MAX_DRAWS} draws: too "
        "many humans for the circle or square (lower n_humans)"
    )


def _norm(dx: float, dy: float) -> float:
    return float(np.linalg.norm((dx, dy)))


def _attributes(
    rs: np.random.RandomState, randomize: bool, v_pref: float = HUMAN_V_PREF
) -> tuple[float, float]:
    """``(v_pref, radius)`` of a new human (``Agent.sample_random_attributes`` when on; ``v_pref``
    [m/s] otherwise, CrowdNav's ``humans.v_pref``)."""
    if not randomize:
        return v_pref, HUMAN_RADIUS
    v_pref = float(rs.uniform(0.5, 1.5))
    radius = float(rs.uniform(0.3, 0.5))
    return v_pref, radius


def circle_crossing_humans(
    rs: np.random.RandomState,
    n: int,
    *,
    circle_radius: float = CIRCLE_RADIUS,
    robot: _Agent = (0.0, -CIRCLE_RADIUS, 0.0, CIRCLE_RADIUS, ROBOT_RADIUS),
    randomize_attributes: bool = False,
    human_v_pref: float = HUMAN_V_PREF,
) -> list[tuple[_Agent, float]]:
    """CrowdNav's circle-crossing humans: ``[((px, py, gx, gy, radius), v_pref), ...]`` (module
    docstring), drawn from ``rs`` with CrowdSim's calls in CrowdSim's order."""
    agents: list[_Agent] = [robot]
    out: list[tuple[_Agent, float]] = []
    for i in range(n):
        v_pref, radius = _attributes(rs, randomize_attributes, human_v_pref)
        for _ in range(MAX_DRAWS):
            angle = rs.random_sample() * np.pi * 2
            px_noise = (rs.random_sample() - 0.5) * v_pref
            py_noise = (rs.random_sample() - 0.5) * v_pref
            px = float(circle_radius * np.cos(angle) + px_noise)
            py = float(circle_radius * np.sin(angle) + py_noise)
            if not any(
                _norm(px - a[0], py - a[1]) < radius + a[4] + DISCOMFORT_DIST
                or _norm(px - a[2], py - a[3]) < radius + a[4] + DISCOMFORT_DIST
                for a in agents
            ):
                break
        else:
            raise _give_up(i, n)
        human = (px, py, -px, -py, radius)
        agents.append(human)
        out.append((human, v_pref))
    return out


def square_crossing_humans(
    rs: np.random.RandomState,
    n: int,
    *,
    square_width: float = SQUARE_WIDTH,
    robot: _Agent = (0.0, -CIRCLE_RADIUS, 0.0, CIRCLE_RADIUS, ROBOT_RADIUS),
    randomize_attributes: bool = False,
    human_v_pref: float = HUMAN_V_PREF,
) -> list[tuple[_Agent, float]]:
    """CrowdNav's square-crossing humans (module docstring), as :func:`circle_crossing_humans`."""
    agents: list[_Agent] = [robot]
    out: list[tuple[_Agent, float]] = []
    for i in range(n):
        v_pref, radius = _attributes(rs, randomize_attributes, human_v_pref)
        sign = -1.0 if rs.random_sample() > 0.5 else 1.0
        for _ in range(MAX_DRAWS):
            px = float(rs.random_sample() * square_width * 0.5 * sign)
            py = float((rs.random_sample() - 0.5) * square_width)
            if not any(
                _norm(px - a[0], py - a[1]) < radius + a[4] + DISCOMFORT_DIST for a in agents
            ):
                break
        else:
            raise _give_up(i, n)
        for _ in range(MAX_DRAWS):
            gx = float(rs.random_sample() * square_width * 0.5 * -sign)
            gy = float((rs.random_sample() - 0.5) * square_width)
            if not any(
                _norm(gx - a[2], gy - a[3]) < radius + a[4] + DISCOMFORT_DIST for a in agents
            ):
                break
        else:
            raise _give_up(i, n)
        human = (px, py, gx, gy, radius)
        agents.append(human)
        out.append((human, v_pref))
    return out


def _draw_humans(
    rs: np.random.RandomState,
    rule: str,
    n: int,
    circle_radius: float,
    square_width: float,
    robot: _Agent,
    randomize_attributes: bool,
    human_v_pref: float,
) -> list[tuple[_Agent, float]]:
    """The humans of ``rule`` (``circle_crossing`` or ``square_crossing``), drawn from ``rs``.

    Raises:
        ValueError: a human cannot be placed in :data:`MAX_DRAWS` draws.
    """
    if rule == "circle_crossing":
        return circle_crossing_humans(
            rs, n, circle_radius=circle_radius, robot=robot,
            randomize_attributes=randomize_attributes, human_v_pref=human_v_pref,
        )  # fmt: skip
    return square_crossing_humans(
        rs, n, square_width=square_width, robot=robot,
        randomize_attributes=randomize_attributes, human_v_pref=human_v_pref,
    )  # fmt: skip


def _positive(description: str, *, above: float = 0.0) -> Any:
    """A finite number > ``above``, described."""
    return Field(gt=above, allow_inf_nan=False, description=description)


@typed_generator("crowdnav")
def crowdnav_scenario(
    case: int,
    *,
    rule: Literal["circle_crossing", "square_crossing"] = "circle_crossing",
    n_humans: Annotated[int, Field(ge=0, le=1000, description="number of humans")] = N_HUMANS,
    circle_radius: Annotated[
        float, _positive("humans' circle, and the robot's start/goal distance [m]")
    ] = CIRCLE_RADIUS,
    square_width: Annotated[float, _positive("side of the square crossing [m]")] = SQUARE_WIDTH,
    phase: Annotated[
        Literal["test", "val", "train"], Field(description="CrowdNav phase of the seeds")
    ] = "test",
    randomize_attributes: Annotated[
        bool, Field(description="humans draw their v_pref and radius")
    ] = False,
    dt: Annotated[float, _positive("integration step [s], a divisor of time_step")] = TIME_STEP,
    time_step: Annotated[float, _positive("decision period of robot and crowd [s]")] = TIME_STEP,
    time_limit: Annotated[
        float, _positive("CrowdNav's time limit [s]; the episode lasts 1 s less", above=1.0)
    ] = TIME_LIMIT,
    robot_radius: Annotated[
        float, _positive("robot disc radius, also the goal tolerance [m]")
    ] = ROBOT_RADIUS,
    v_pref: Annotated[float, _positive("robot V_max [m/s]")] = ROBOT_V_PREF,
    u_max: Annotated[float, _positive("U_max of the unicycle variant [rad/s]")] = UNICYCLE_U_MAX,
    kinematics: Annotated[
        Literal["turn-then-move", "arc"],
        Field(description="the unicycle variant's kinematics (CrowdNav's: turn-then-move)"),
    ] = "turn-then-move",
    accel_max: Annotated[
        float | None,
        Field(
            gt=0,
            allow_inf_nan=False,
            description="the robot's largest speed change [m/s^2] (omitted: at once)",
        ),
    ] = None,
    turn_accel_max: Annotated[
        float | None,
        Field(
            gt=0,
            allow_inf_nan=False,
            description="the unicycle's largest turn-rate change [rad/s^2] (omitted: at once)",
        ),
    ] = None,
    sensing_range: Annotated[
        float, _positive("the robot sees humans within this [m]")
    ] = SENSING_RANGE,
    controller: Annotated[str, Field(description="the scene's own law")] = "orca-holonomic-v1",
    controller_params: Annotated[dict[str, Any] | None, Field(description="its parameters")] = None,
    robot_visible: Annotated[
        bool, Field(description="the humans see the robot and avoid it")
    ] = False,
    human_policy: Annotated[
        Literal["orca", "social_force"], Field(description="the humans' policy")
    ] = "orca",
    human_v_pref: Annotated[float, _positive("the humans' preferred speed [m/s]")] = HUMAN_V_PREF,
    velocities: Annotated[
        Literal["known", "estimated"], Field(description="the humans' velocities, as sensed")
    ] = "known",
    position_noise: Annotated[
        float,
        Field(ge=0, allow_inf_nan=False, description="std of the sensed centres [m] (estimated)"),
    ] = 0.0,
    bodies: Annotated[
        Literal["exact", "lidar"],
        Field(description="the humans as read exactly, or as a lidar scan shows them"),
    ] = "exact",
    lidar_beams: Annotated[
        int, Field(ge=1, le=100_000, description="lidar beams (bodies=lidar)")
    ] = 360,
    lidar_noise: Annotated[
        float, Field(ge=0, allow_inf_nan=False, description="lidar range noise std [m]")
    ] = 0.01,
) -> Scenario:
    """CrowdNav's test case ``case`` of ``rule`` (module docstring for every choice and source).

    Args:
        case: the case number (numpy legacy seed ``PHASE_OFFSET[phase] + case``), >= 0.
        rule: ``circle_crossing`` or ``square_crossing``.
        n_humans: number of humans.
        circle_radius: radius of the humans' circle, and the robot's start/goal distance [m].
        square_width: side of the square crossing [m].
        phase: CrowdNav's phase whose seeds are used (``test``: 1000 + case).
        randomize_attributes: humans draw their ``v_pref`` and radius.
        dt: integration step [s] (a divisor of ``time_step``; smaller = finer collision checks).
        time_step: the robot's and the crowd's decision period [s].
        robot_visible: the humans see the robot and avoid it (CrowdNav's ``visible = true``);
            the test protocol's robot is invisible.
        human_policy: the humans' policy: ``orca`` (CrowdNav's test protocol) or ``social_force``
            (Helbing and Molnár's model, :mod:`uvnav.obstacles.social_force`; CrowdNav offers a
            social-force policy too, through another implementation).
        time_limit: CrowdNav's time limit [s]; the episode lasts ``time_limit - 1``.
        robot_radius: robot disc radius [m] (also the goal tolerance).
        v_pref: robot V_max [m/s].
        u_max: U_max of the unicycle variant [rad/s].
        kinematics: how the unicycle variant moves: ``turn-then-move`` (CrowdNav's
            ``ActionRot``: the period's turn at once, then straight) or ``arc`` (the thesis's).
        accel_max, turn_accel_max: the unicycle variant's acceleration limits [m/s^2], [rad/s^2]
            (:class:`~uvnav.dynamics.unicycle.UnicycleSpec`; ``None``: the command at once).
        sensing_range: the robot sees humans within this [m].
        controller: the scene's own law.
        controller_params: its parameters (``orca-holonomic-v1``: CrowdNav's robot ORCA).
        human_v_pref: the humans' preferred speed [m/s] (CrowdNav's ``humans.v_pref``, 1 m/s; it
            also scales the circle-crossing start noise, as in CrowdSim); ignored when
            ``randomize_attributes`` draws it.
        velocities: what the robot knows of the humans' velocities (the scene's sensing block):
            ``known`` (CrowdNav's ``coordinates`` sensor, exact) or ``estimated`` (finite
            differences of the sensed centres, :mod:`uvnav.prediction.finite_difference`).
        position_noise: std of the Gaussian noise on the sensed centres [m] when ``estimated``.
        bodies: ``exact`` readings of the humans, or ``lidar``: the humans a lidar of
            ``lidar_beams`` beams over a full turn with ``lidar_noise`` [m] range noise and the
            sensing range as its range shows (:mod:`uvnav.sensors.scan_bodies`; needs
            ``velocities=estimated``).
    """
    case = int(case)
    short = "circle" if rule == "circle_crossing" else "square"
    if case < 0:
        raise ScenarioError(f"crowdnav-{short}:{case}", "seed", f"must be >= 0 (got {case})")
    if position_noise > 0 and velocities == "known":
        raise ScenarioError(
            f"crowdnav-{short}:{case}",
            "params.position_noise",
            "needs velocities='estimated' (known velocities are exact)",
        )
    seed = PHASE_OFFSET[phase] + case
    if seed >= 2**32:  # numpy's legacy seeds are 32-bit
        raise ScenarioError(
            f"crowdnav-{short}:{case}",
            "seed",
            f"CrowdNav's cases are numpy legacy seeds {PHASE_OFFSET[phase]} + case < 2**32: the "
            f"case must be below {2**32 - PHASE_OFFSET[phase]} (got {case})",
        )
    rs = np.random.RandomState(seed)
    robot: _Agent = (0.0, -circle_radius, 0.0, circle_radius, robot_radius)
    try:
        humans = _draw_humans(
            rs, rule, int(n_humans), circle_radius, square_width, robot, randomize_attributes,
            human_v_pref,
        )  # fmt: skip
    except ValueError as exc:
        raise ScenarioError(f"crowdnav-{short}:{case}", "n_humans", str(exc)) from None
    obstacles = [
        {
            "name": f"human-{i}",
            "body": {"disc": radius},
            "start": {"position": [px, py], "heading": 0.0},
            "motion": (
                {
                    "type": "orca_crowd",
                    "goal": [gx, gy],
                    "v_pref": hv,
                    "period": time_step,
                    "sees_robot": bool(robot_visible),
                }
                if human_policy == "orca"
                else {
                    "type": "social_force",
                    "goal": [gx, gy],
                    "v_pref": hv,
                    "sees_robot": bool(robot_visible),
                }
            ),
        }
        for i, ((px, py, gx, gy, radius), hv) in enumerate(humans)
    ]
    if controller_params is None:
        controller_params = dict(CROWDNAV_ORCA_PARAMS) if controller == "orca-holonomic-v1" else {}
    sees = "see" if robot_visible else "do not see"
    policy = "ORCA" if human_policy == "orca" else "social-force"
    data: dict[str, Any] = {
        "name": f"crowdnav-{short}-{case}",
        "description": (
            f"CrowdNav {rule.replace('_', ' ')} ({phase} case {case}, numpy seed {seed}; Chen et "
            f"al., ICRA 2019): {len(humans)} {policy} humans that {sees} the robot; robot from "
            f"(0, {-circle_radius:g}) to (0, {circle_radius:g}), time limit {time_limit:g} s "
            f"(acting as {time_limit - 1:g} s, as in CrowdSim)."
        ),
        "dim": 2,
        "dt": dt,
        "control_period": time_step,
        "t_max": time_limit - 1.0,
        "goal_tolerance": robot_radius,
        "robot": crossing_robot(
            circle_radius, v_pref, u_max, robot_radius, kinematics, accel_max, turn_accel_max
        ),
        "sensing": {
            "range": sensing_range,
            "velocities": velocities,
            "position_noise": float(position_noise),
            "bodies": bodies,
            **(
                {
                    "lidar": {
                        "n_rays": lidar_beams,
                        "max_range": sensing_range,
                        "noise_std": lidar_noise,
                    }
                }
                if bodies == "lidar"
                else {}
            ),
        },
        "obstacles": obstacles,
        "controller": {"name": controller, "params": dict(controller_params)},
    }
    return scenario_from_dict(data, source=f"crowdnav-{short}:{case}")


#: ``crowdnav-circle:<case>`` and ``crowdnav-square:<case>``: CrowdNav's test cases
#: (:func:`crowdnav_scenario` of each rule, its other parameters typed and checked)
crowdnav_circle = typed_generator("crowdnav-circle")(
    partial(crowdnav_scenario, rule="circle_crossing")
)
crowdnav_square = typed_generator("crowdnav-square")(
    partial(crowdnav_scenario, rule="square_crossing")
)
