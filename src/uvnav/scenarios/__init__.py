"""Layer 5: scenario schema, YAML loading, the built-in scenario library and random generators.

Public API::

    Scenario, ScenarioError
    list_builtin(), load_scenario(name_or_path), scenario_from_dict(data, source)
    build_episode(scenario, seed) -> uvnav.sim.EpisodeSetup
    check_constraints(scenario) -> list[str]          # thesis (2.6)-(2.8)
    validate_for_controller(scenario, controller_name)
    random_ch2_scenario(seed, n_obstacles=None, ...)
    crowd_crossing_scenario(seed, dataset='eth', v_max=1.2, ...)   # real pedestrians (ETH)
"""

from uvnav.scenarios.build import (
    build_episode,
    check_constraints,
    obstacle_bounds,
    validate_for_controller,
)
from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.generators import (
    GENERATORS,
    crowd_crossing_scenario,
    generate,
    random_ch2_scenario,
)
from uvnav.scenarios.loader import (
    builtin_text,
    list_builtin,
    load_scenario,
    parse_yaml,
    scenario_from_dict,
    scenario_text,
    scenario_to_dict,
    scenario_to_yaml,
)
from uvnav.scenarios.schema import (
    BodySpec,
    ConstantMotion,
    ControllerSpec,
    CrowdSpec,
    LidarSpec,
    ObstacleSpec,
    ObstacleStart,
    OrcaCrowdMotion,
    RandomTurnMotion,
    ReplayMotion,
    RobotSpec,
    Scenario,
    SensingSpec,
    WaypointsMotion,
)

__all__ = [
    "GENERATORS",
    "BodySpec",
    "ConstantMotion",
    "ControllerSpec",
    "CrowdSpec",
    "LidarSpec",
    "ObstacleSpec",
    "ObstacleStart",
    "OrcaCrowdMotion",
    "RandomTurnMotion",
    "ReplayMotion",
    "RobotSpec",
    "Scenario",
    "ScenarioError",
    "SensingSpec",
    "WaypointsMotion",
    "build_episode",
    "builtin_text",
    "check_constraints",
    "crowd_crossing_scenario",
    "generate",
    "list_builtin",
    "load_scenario",
    "obstacle_bounds",
    "parse_yaml",
    "random_ch2_scenario",
    "scenario_from_dict",
    "scenario_text",
    "scenario_to_dict",
    "scenario_to_yaml",
    "validate_for_controller",
]
