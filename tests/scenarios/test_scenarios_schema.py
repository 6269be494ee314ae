"""Schema behaviour: round trips, defaults, one-line errors naming file and field."""

from __future__ import annotations

from pathlib import Path

import pytest

from uvnav.scenarios import (
    Scenario,
    ScenarioError,
    list_builtin,
    load_scenario,
    parse_yaml,
    random_ch2_scenario,
    scenario_from_dict,
    scenario_to_yaml,
)

BASE = """\
name: t
dt: 0.1
t_max: 30
robot: {start: [0, 0], goal: [10, 10], v_max: 0.7, u_max: 1.4}
"""


def obstacle(body: str = "{disc: 0.5}", start: str = "{position: [5, 3]}", motion: str = "") -> str:
    motion = motion or "{type: constant, velocity: [0, 0]}"
    return f"obstacles:\n  - body: {body}\n    start: {start}\n    motion: {motion}\n"


# (file text, field path, problem fragment)
BAD_CASES = [
    pytest.param(
        "name: t\nrobot: {start: [0, 0\ngoal: 3\n", "line 3", "malformed YAML", id="malformed"
    ),
    pytest.param("name: t\nname: u\n", "line 2", "duplicate key 'name'", id="duplicate-key"),
    pytest.param(BASE + "robto: 1\n", "robto", "unknown field (allowed: name,", id="unknown-top"),
    pytest.param(
        BASE + obstacle(motion="{type: random_turn, sped: [0.1, 0.2], turn_rate: [0, 0]}"),
        "obstacles.0.motion.sped",
        "unknown field (allowed: type, speed,",
        id="unknown-nested",
    ),
    pytest.param(
        BASE.replace("dt: 0.1", "dt: fast"), "dt", "expected a number (got 'fast')", id="type"
    ),
    pytest.param(
        BASE.replace("v_max: 0.7", "v_max: -1"), "robot.v_max", "must be > 0 (got -1)", id="v_max"
    ),
    pytest.param(
        BASE.replace("u_max: 1.4", "u_max: 0"), "robot.u_max", "must be > 0 (got 0)", id="u_max"
    ),
    pytest.param(
        BASE.replace("u_max: 1.4", "u_max: 1.4, radius: -0.1"),
        "robot.radius",
        "must be >= 0 (got -0.1)",
        id="radius",
    ),
    pytest.param(BASE.replace("dt: 0.1", "dt: 0"), "dt", "must be > 0 (got 0)", id="dt"),
    pytest.param(
        BASE.replace("dt: 0.1", "dt: 0.1\ncontrol_period: 0.15"),
        "control_period",
        "positive multiple of dt",
        id="control-period",
    ),
    pytest.param(
        BASE + obstacle(start="{position: [10, 10.3]}", body="{disc: 1.0}"),
        "robot.goal",
        "inside obstacle 0",
        id="goal-inside",
    ),
    pytest.param(
        BASE + obstacle(start="{position: [0.5, 0.5]}", body="{disc: 0.65}"),
        "robot.start",
        "overlaps obstacle 0",
        id="start-overlap",
    ),
    pytest.param(
        BASE + obstacle(body="{polygon: [[0, 0], [1, 1]]}"),
        "obstacles.0.body.polygon",
        "at least 3 vertices (got 2)",
        id="polygon-2-vertices",
    ),
    pytest.param(
        BASE + obstacle(body="{polygon: [[0, 0], [1, 1], [1, 0], [0, 1]]}"),
        "obstacles.0.body.polygon",
        "not simple: Self-intersection",
        id="polygon-self-intersecting",
    ),
    pytest.param(
        BASE + obstacle(motion="{type: random_turn, speed: [0.4, 0.1], turn_rate: [-0.1, 0.1]}"),
        "obstacles.0.motion.speed",
        "min 0.4 > max 0.1",
        id="speed-range",
    ),
    pytest.param(
        BASE + obstacle(motion="{type: teleport}"),
        "obstacles.0.motion",
        "unknown 'type' 'teleport'",
        id="motion-type",
    ),
    pytest.param(
        BASE + obstacle(body="{disc: 0.5, polygon: [[0, 0], [1, 0], [0, 1]]}"),
        "obstacles.0.body",
        "exactly one of 'polygon'",
        id="two-bodies",
    ),
    pytest.param(
        BASE.replace("start: [0, 0]", "start: [0, 0, 0]"),
        "robot.start",
        "at most 2 item(s) (got 3)",
        id="point-length",
    ),
    pytest.param(
        BASE.replace("start: [0, 0]", "start: [1.0e15, 0]"),
        "robot.start.0",
        "1e+15 is outside the modelled range |x| <= 1e+06 m",
        id="coordinate",
    ),
    pytest.param(
        BASE + obstacle(body="{polygon: [[0, 0], [1, 0], [0, -2.0e6]]}"),
        "obstacles.0.body.polygon.2.1",
        "-2e+06 is outside the modelled range",
        id="polygon-vertex",
    ),
    pytest.param(
        BASE.replace("v_max: 0.7", "v_max: 1.0e300"),  # YAML 1.1: a string pydantic converts
        "robot.v_max",
        "1e+300 is above the limit of 1e+09",
        id="magnitude-of-a-string-number",
    ),
]


@pytest.mark.parametrize(("text", "field", "problem"), BAD_CASES)
def test_bad_input_is_one_line_naming_file_and_field(
    tmp_path: Path, text: str, field: str, problem: str
) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: {field}: "), message
    assert problem in message
    assert info.value.path == field


def test_error_message_matches_design_example(tmp_path: Path) -> None:
    path = tmp_path / "thesis.yaml"
    path.write_text(BASE.replace("v_max: 0.7", "v_max: -1"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(info.value) == f"{path}: robot.v_max: must be > 0 (got -1)"


def test_missing_file_and_unknown_name() -> None:
    with pytest.raises(ScenarioError, match=r"nowhere\.yaml: no such file"):
        load_scenario("nowhere.yaml")
    with pytest.raises(ScenarioError, match="no such file or built-in scenario"):
        load_scenario("no-such-scene")
    with pytest.raises(ScenarioError, match="random-ch2:<non-negative integer seed>"):
        load_scenario("random-ch2:x")


def test_non_mapping_and_empty_files_are_rejected() -> None:
    with pytest.raises(ScenarioError, match="expected a mapping"):
        parse_yaml("- 1\n- 2\n", "list.yaml")
    with pytest.raises(ScenarioError, match="empty file"):
        parse_yaml("", "empty.yaml")
    with pytest.raises(ScenarioError, match=r"<dict>: <root>: expected a mapping"):
        scenario_from_dict([1, 2])  # type: ignore[arg-type]


@pytest.mark.parametrize("name", [*list_builtin(), "random-ch2:5"])
def test_yaml_round_trip(name: str) -> None:
    scenario = load_scenario(name)
    again = scenario_from_dict(parse_yaml(scenario_to_yaml(scenario), "again.yaml"), "again.yaml")
    assert again == scenario
    assert again.model_dump() == scenario.model_dump()


def test_defaults_are_filled() -> None:
    sc = scenario_from_dict(parse_yaml(BASE.replace("dt: 0.1", "dt: 0.05"), "x.yaml"))
    assert sc.control_period == 0.05  # defaults to dt
    assert sc.goal_tolerance == 0.1
    assert sc.robot.radius == 0.1
    assert sc.robot.initial_heading() == pytest.approx(0.7853981633974483)  # facing the goal
    assert sc.sensing.velocities == "known"
    assert sc.obstacles == []
    assert sc.controller.name == "zhang2019-v1"


def test_json_schema_forbids_extra_fields_everywhere() -> None:
    schema = Scenario.model_json_schema()
    assert schema["additionalProperties"] is False
    for name, definition in schema["$defs"].items():
        assert definition.get("additionalProperties") is False, name
    v_max = schema["$defs"]["RobotSpec"]["properties"]["v_max"]
    assert v_max["exclusiveMinimum"] == 0
    assert "[m/s]" in v_max["description"]


def test_scenarios_are_immutable() -> None:
    sc = random_ch2_scenario(1)
    with pytest.raises(ValueError, match="frozen"):
        sc.dt = 1.0  # type: ignore[misc]


def test_replay_and_waypoint_obstacles_default_their_start(tmp_path: Path) -> None:
    text = BASE + (
        "obstacles:\n"
        "  - body: {disc: 0.3}\n"
        "    motion: {type: replay, times: [0, 10], positions: [[3, 0], [3, 5]]}\n"
        "  - body: {disc: 0.3}\n"
        "    motion: {type: waypoints, points: [[6, 0], [6, 4]], speed: 0.2}\n"
    )
    sc = scenario_from_dict(parse_yaml(text, "x.yaml"))
    assert sc.obstacles[0].start is None
    bad = text.replace(
        "motion: {type: replay", "start: {position: [9, 9]}\n    motion: {type: replay"
    )
    with pytest.raises(
        ScenarioError, match=r"obstacles\.0\.start\.position: must match the replayed"
    ):
        scenario_from_dict(parse_yaml(bad, "x.yaml"), "x.yaml")
    constant_without_start = BASE + (
        "obstacles:\n  - body: {disc: 0.3}\n    motion: {type: constant, velocity: [0, 0]}\n"
    )
    with pytest.raises(
        ScenarioError, match=r"obstacles\.0\.start: required for motion type 'constant'"
    ):
        scenario_from_dict(parse_yaml(constant_without_start, "x.yaml"), "x.yaml")
