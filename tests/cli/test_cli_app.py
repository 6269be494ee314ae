"""The ``uvnav`` command line: outputs, exit statuses, one-line errors (DESIGN §3, §6)."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
import types
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from uvnav.cli.app import app, parse_params
from uvnav.scenarios import Scenario, list_builtin, load_scenario, parse_yaml, scenario_from_dict
from uvnav.sim import METRIC_NAMES

runner = CliRunner()

FREE_SCENE = """\
name: free-lane
dt: 0.1
t_max: 30
goal_tolerance: 0.1
robot: {start: [0, 0], goal: [6, 0], v_max: 0.7, u_max: 1.4}
obstacles:
  - body: {polygon: [[-0.6, -0.4], [0.7, -0.5], [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]]}
    start: {position: [3, 4], heading: 0}
    motion: {type: random_turn, speed: [0.05, 0.1], turn_rate: [-0.05, 0.05], arena: [0, 3, 6, 6]}
controller: {name: straight-v1}
"""


def invoke(*args: str) -> Any:
    return runner.invoke(app, list(args))


def assert_one_line_error(result: Any, code: int, *fragments: str) -> str:
    assert result.exit_code == code, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: ")
    for fragment in fragments:
        assert fragment in lines[0]
    assert "Traceback" not in result.output
    assert isinstance(result.exception, SystemExit)
    return lines[0]


@pytest.fixture
def free_scene(tmp_path: Path) -> Path:
    path = tmp_path / "free.yaml"
    path.write_text(FREE_SCENE)
    return path


# ------------------------------------------------------------------------------------ simulate


def test_simulate_json_is_one_object_with_every_metric(free_scene: Path) -> None:
    result = invoke("simulate", str(free_scene), "--json", "--seed", "3")
    assert result.exit_code == 0, result.output
    record = json.loads(result.stdout)  # the whole stdout is exactly one JSON document
    assert isinstance(record, dict)
    assert set(METRIC_NAMES) <= set(record)
    assert record["scenario"] == "free-lane"
    assert record["controller"] == "straight-v1"
    assert record["seed"] == 3
    assert record["status"] == "success" and record["success"] is True
    assert record["collision"] is False
    assert record["path_length"] == pytest.approx(5.9, abs=0.11)  # straight 6 m minus the tolerance
    assert record["detour_ratio"] == pytest.approx(1.0, abs=0.02)


def test_simulate_builtin_by_name_with_controller_override() -> None:
    result = invoke("simulate", "open-field", "--controller", "straight-v1", "--json")
    assert result.exit_code == 0, result.output
    record = json.loads(result.stdout)
    assert record["success"] is True and record["min_clearance"] > 1.0


def test_simulate_table_lists_the_metrics(free_scene: Path) -> None:
    result = invoke("simulate", str(free_scene))
    assert result.exit_code == 0, result.output
    for name in METRIC_NAMES:
        assert name in result.stdout
    assert "success" in result.stdout.splitlines()[0] + result.stdout.splitlines()[1]


def test_param_overrides_reach_the_controller(free_scene: Path) -> None:
    fast = json.loads(invoke("simulate", str(free_scene), "--json").stdout)
    slow = json.loads(invoke("simulate", str(free_scene), "--json", "-p", "slow_radius=3.0").stdout)
    assert slow["params"] == {"slow_radius": 3.0}
    assert slow["success"] and slow["time_to_goal"] > fast["time_to_goal"] + 1.0


def test_simulate_is_reproducible_and_seed_dependent() -> None:
    a = json.loads(
        invoke("simulate", "thesis-ch2-one-obstacle", "-c", "straight-v1", "--json").stdout
    )
    b = json.loads(
        invoke("simulate", "thesis-ch2-one-obstacle", "-c", "straight-v1", "--json").stdout
    )
    c = json.loads(
        invoke(
            "simulate", "thesis-ch2-one-obstacle", "-c", "straight-v1", "--json", "--seed", "1"
        ).stdout
    )
    keep = [k for k in METRIC_NAMES if not k.startswith("decision_us")]
    assert [a[k] for k in keep] == [b[k] for k in keep]
    assert a["min_clearance"] != c["min_clearance"]


def test_plot_calls_the_figure_module(
    free_scene: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[tuple[Any, ...]] = []
    fake = types.ModuleType("uvnav.viz.episode")
    fake.plot_outcome = lambda out, path: calls.append((out.result, out.setup, path))  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "uvnav.viz.episode", fake)
    out = tmp_path / "ep.png"
    result = invoke("simulate", str(free_scene), "--json", "--plot", str(out))
    assert result.exit_code == 0, result.output
    json.loads(result.stdout)  # stdout stays pure JSON; the note goes to stderr
    assert f"wrote {out}" in result.stderr
    ((res, setup, path),) = calls
    assert path == out and res.status == "success" and res.trajectory is not None
    assert len(setup.obstacles) == 1


def test_plot_without_figure_module_is_one_line_error(
    free_scene: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "uvnav.viz.figures", None)  # import raises ImportError
    result = invoke("simulate", str(free_scene), "--plot", "x.png")
    assert_one_line_error(result, 1, "plotting (--plot) is not available", "uvnav.viz.figures")


# ------------------------------------------------------------------------------- user errors

BAD_FILES = [
    pytest.param("name: t\nrobot: {start: [0, 0\n", "line 3", id="malformed-yaml"),
    pytest.param(FREE_SCENE + "extra: 1\n", "extra: unknown field", id="unknown-field"),
    pytest.param(
        FREE_SCENE.replace("t_max: 30", "t_max: soon"), "t_max: expected a number", id="type"
    ),
    pytest.param(
        FREE_SCENE.replace("v_max: 0.7", "v_max: -1"),
        "robot.v_max: must be > 0 (got -1)",
        id="v_max",
    ),
    pytest.param(
        FREE_SCENE.replace("u_max: 1.4", "u_max: 0"), "robot.u_max: must be > 0", id="u_max"
    ),
    pytest.param(
        FREE_SCENE.replace("u_max: 1.4", "u_max: 1.4, radius: -1"),
        "robot.radius: must be >= 0",
        id="radius",
    ),
    pytest.param(FREE_SCENE.replace("dt: 0.1", "dt: -0.1"), "dt: must be > 0", id="dt"),
    pytest.param(
        FREE_SCENE.replace("dt: 0.1", "dt: 0.1\ncontrol_period: 0.25"),
        "control_period: must be a positive multiple",
        id="control-period",
    ),
    pytest.param(
        FREE_SCENE.replace("goal: [6, 0]", "goal: [3, 4]"),
        "robot.goal: lies inside obstacle 0",
        id="goal-inside",
    ),
    pytest.param(
        FREE_SCENE.replace("position: [3, 4]", "position: [0.3, 0.3]"),
        "robot.start: robot disc",
        id="start-overlap",
    ),
    pytest.param(
        FREE_SCENE.replace(
            "[[-0.6, -0.4], [0.7, -0.5], [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]]",
            "[[0, 0], [1, 1], [1, 0], [0, 1]]",
        ),
        "obstacles.0.body.polygon: polygon is not simple",
        id="self-intersecting",
    ),
    pytest.param(
        FREE_SCENE.replace(", [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]", ""),
        "obstacles.0.body.polygon: a polygon needs at least 3",
        id="two-vertices",
    ),
    pytest.param(
        FREE_SCENE.replace("speed: [0.05, 0.1]", "speed: [0.1, 0.05]"),
        "obstacles.0.motion.speed: min 0.1 > max 0.05",
        id="speed-range",
    ),
]


@pytest.mark.parametrize(("text", "fragment"), BAD_FILES)
def test_bad_scenario_file_gives_exit_2_and_one_line(
    tmp_path: Path, text: str, fragment: str
) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    line = assert_one_line_error(invoke("simulate", str(path)), 2, fragment)
    assert line.startswith(f"error: {path}: ")
    line = assert_one_line_error(invoke("scenarios", "validate", str(path)), 2, fragment)
    assert line.startswith(f"error: {path}: ")


def test_missing_file_unknown_controller_and_bad_params(free_scene: Path) -> None:
    assert_one_line_error(invoke("simulate", "missing.yaml"), 2, "missing.yaml: no such file")
    assert_one_line_error(
        invoke("simulate", str(free_scene), "-c", "nope-v9"), 2, "unknown controller 'nope-v9'"
    )
    assert_one_line_error(
        invoke("simulate", str(free_scene), "-p", "slow_radius"),
        2,
        "--param 'slow_radius'",
        "KEY=VALUE",
    )
    assert_one_line_error(invoke("simulate", str(free_scene), "-p", "=3"), 2, "KEY=VALUE")
    assert_one_line_error(
        invoke("simulate", str(free_scene), "-p", "bogus=1"),
        2,
        "controller straight-v1",
        "unknown parameter(s) bogus",
    )
    assert_one_line_error(
        invoke("report", "no-such.sqlite"), 2, "no-such.sqlite: no such database file"
    )
    assert_one_line_error(
        invoke("controllers", "show", "nope-v9"), 2, "unknown controller 'nope-v9'"
    )
    assert_one_line_error(invoke("scenarios", "show", "nope"), 2, "no such file or built-in")


def test_usage_errors_are_one_line_too() -> None:
    assert_one_line_error(invoke("simulate"), 2, "Missing argument", "uvnav simulate --help")
    assert_one_line_error(invoke("simulate", "open-field", "--seed", "abc"), 2, "--seed")


def test_parse_params_reads_yaml_values() -> None:
    assert parse_params(["a=0.5", "b=true", "c=[1, 2]", "d=fast", "e="]) == {
        "a": 0.5,
        "b": True,
        "c": [1, 2],
        "d": "fast",
        "e": "",
    }


# ----------------------------------------------------------------------------------- scenarios


def test_scenarios_list_json_and_table() -> None:
    result = invoke("scenarios", "list", "--json")
    assert result.exit_code == 0
    rows = json.loads(result.stdout)
    flat = [r["name"] for r in rows if r["kind"] == "nav2d" and r["obstacles"] is not None]
    assert flat == [n for n in list_builtin() if load_scenario(n).dim == 2]
    assert all(r["description"] for r in rows if r["kind"] == "nav2d")
    table = invoke("scenarios", "list")
    assert table.exit_code == 0
    for name in list_builtin():
        assert name in table.stdout


def test_scenarios_show_prints_loadable_yaml() -> None:
    raw = invoke("scenarios", "show", "thesis-ch2-one-obstacle")
    assert raw.exit_code == 0 and raw.stdout.startswith("#")
    resolved = invoke("scenarios", "show", "thesis-ch2-one-obstacle", "--resolved")
    expected = load_scenario("thesis-ch2-one-obstacle")
    for result in (raw, resolved):
        assert scenario_from_dict(parse_yaml(result.stdout, "out.yaml")) == expected
    generated = invoke("scenarios", "show", "random-ch2:7")
    assert scenario_from_dict(parse_yaml(generated.stdout, "g.yaml")) == load_scenario(
        "random-ch2:7"
    )


def test_scenarios_schema_is_the_model_schema() -> None:
    result = invoke("scenarios", "schema", "--kind", "nav2d")
    assert result.exit_code == 0
    assert json.loads(result.stdout) == json.loads(json.dumps(Scenario.model_json_schema()))


def test_scenarios_validate_reports_each_file(free_scene: Path, tmp_path: Path) -> None:
    twitchy = tmp_path / "twitchy.yaml"  # valid, but breaks (2.8)
    twitchy.write_text(
        FREE_SCENE.replace("turn_rate: [-0.05, 0.05]", "turn_rate: [-0.3, 0.3]").replace(
            "speed: [0.05, 0.1]", "speed: [0.1, 0.4]"
        )
    )
    bad = tmp_path / "bad.yaml"
    bad.write_text(FREE_SCENE.replace("v_max: 0.7", "v_max: 0"))
    ok = invoke("scenarios", "validate", str(free_scene), "thesis-ch2-six-obstacles")
    assert ok.exit_code == 0, ok.output
    assert ok.stdout.splitlines() == [
        f"OK {free_scene} [nav2d]",
        "OK thesis-ch2-six-obstacles [nav2d]",
    ]
    mixed = invoke("scenarios", "validate", str(free_scene), str(twitchy), str(bad))
    assert mixed.exit_code == 2
    assert f"OK {free_scene} [nav2d]" in mixed.stdout
    assert f"OK {twitchy} [nav2d] (1 warning)" in mixed.stdout
    assert "(2.8) Delta distance" in mixed.stdout
    assert mixed.stderr.strip() == f"error: {bad}: robot.v_max: must be > 0 (got 0)"


# --------------------------------------------------------------------------------- controllers


def test_controllers_list_and_show() -> None:
    listed = json.loads(invoke("controllers", "list", "--json").stdout)
    assert "straight-v1" in [row["name"] for row in listed]
    shown = json.loads(invoke("controllers", "show", "straight-v1", "--json").stdout)
    (param,) = shown["params"]
    assert param["name"] == "slow_radius" and param["default"] == 0.0
    assert "[m]" in param["doc"]
    table = invoke("controllers", "show", "straight-v1")
    assert table.exit_code == 0 and "slow_radius" in table.stdout


def test_controllers_list_shows_every_vehicle_and_filters_by_one() -> None:
    listed = json.loads(invoke("controllers", "list", "--json").stdout)
    by_name = {row["name"]: row for row in listed}
    assert by_name["zhang2019-v1"]["vehicle"] == "unicycle"
    assert by_name["zhang2020-3d-v1"]["vehicle"] == "vehicle3d"
    assert by_name["zhang2022-uuv3d-v1"]["sensing"] == "sonar-array"
    assert by_name["zhang2022-uuv2d-v1"]["vehicle"] == "uuv2d"
    only3d = json.loads(invoke("controllers", "list", "--vehicle", "vehicle3d", "--json").stdout)
    assert {row["vehicle"] for row in only3d} == {"vehicle3d"}
    assert "zhang2020-3d-v1" in {row["name"] for row in only3d}
    bad = invoke("controllers", "list", "--vehicle", "boat")
    assert bad.exit_code == 2
    assert bad.stderr.strip().startswith("error: --vehicle: unknown vehicle 'boat'")


def test_controllers_list_fits_an_80_column_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    from rich.console import Console

    import uvnav.cli.controllers as cc

    monkeypatch.setattr(cc, "_console", lambda: Console(width=80, highlight=False))
    out = invoke("controllers", "list").stdout.splitlines()
    listed = json.loads(invoke("controllers", "list", "--json").stdout)
    assert max(len(line) for line in out) <= 80
    assert len(out) < 4 * len(listed) + 5  # a name line and a few summary lines per law
    named = {line.split()[0] for line in out if line and not line.startswith(" ")}
    assert {row["name"] for row in listed} <= named
    v1 = next(line for line in out if line.startswith("zhang2019-v1 "))
    assert v1.endswith("*") and out[-1].startswith("* requires obstacles slower")


def test_controllers_show_wraps_long_descriptions_in_a_pipe() -> None:
    from uvnav.cli.controllers import DESCRIPTION_WIDTH

    out = invoke("controllers", "show", "zhang2019-v2").stdout
    rows = [line for line in out.splitlines() if line.startswith("│")]
    assert rows and max(len(line) for line in rows) <= 80 + DESCRIPTION_WIDTH
    assert any(line.startswith("│ route_grid_weight ") for line in rows)  # names whole


def test_controllers_show_reads_without_python_types_or_markup() -> None:
    shown = json.loads(invoke("controllers", "show", "zhang2019-v1", "--json").stdout)
    by_name = {p["name"]: p for p in shown["params"]}
    assert by_name["tangent_rule"]["type"] == "side | min_beta"
    assert "``" not in by_name["tangent_rule"]["doc"] and '"side"' in by_name["tangent_rule"]["doc"]


# ------------------------------------------------------------------------------- run / report


@dataclass
class FakeSummary:
    table: list[dict[str, str]]
    db_path: Path
    report_path: Path | None
    figures: list[Path] = field(default_factory=list)
    sections: list[Any] = field(default_factory=list)


def test_run_prints_the_comparison_table(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[dict[str, Any]] = []

    from uvnav.experiments.sections import ChapterRenderers, ChapterSection

    row = {
        "quantity": "path length Fig. 2.10 (Zhang)",
        "thesis": "14.9 m",
        "measured": "15.2 m",
        "note": "geometry chosen from the text",
    }
    long_title = "Chapter 2 — a unicycle among moving, rotating, non-convex obstacles " * 2

    def reproduce(ctx: Any) -> FakeSummary:
        calls.append({f.name: getattr(ctx, f.name) for f in dataclasses.fields(ctx)})
        return FakeSummary(
            table=[row],
            db_path=ctx.results_dir / "uvnav.sqlite",
            report_path=ctx.report_dir / "index.html",
            figures=[ctx.report_dir / "a.png", ctx.report_dir / "b.png"],
            sections=[ChapterSection("ch2", long_title, "", rows=[row])],
        )

    import uvnav.experiments
    from uvnav.viz.reproduction import render_reproduction

    monkeypatch.setattr(uvnav.experiments, "run_all", reproduce)
    res_dir, rep_dir = tmp_path / "res", tmp_path / "rep"
    result = runner.invoke(
        app,
        ["run", "--workers", "3", "--results", str(res_dir), "--report", str(rep_dir)],
        env={"COLUMNS": "200"},
    )
    assert result.exit_code == 0, result.output
    renderers = calls[0].pop("renderers")
    assert calls == [
        {
            "results_dir": res_dir,
            "report_dir": rep_dir,
            "full": False,
            "workers": 3,
            "seeds": None,
            "start_seed": 0,
            "progress": True,
            "render": render_reproduction,
            "fresh": False,
            "size": None,
        }
    ]
    # every chapter with figures gets its renderer (Chapters 3-7 and issue 9)
    assert isinstance(renderers, ChapterRenderers)
    assert all(
        getattr(renderers, k) is not None for k in ("ch3", "ch4", "ch5", "ch6", "ch7", "beyond")
    )
    screen = result.stdout.splitlines()
    assert screen[0] == "uvnav run: 1 experiments, 1 reproduced"
    assert "thesis 14.9 m | uvnav 15.2 m -> reproduced" in result.stdout  # within 5 %
    summary = screen[: next(i for i, line in enumerate(screen) if line.startswith("wrote"))]
    assert len(summary) <= 40 and max(len(line) for line in summary) <= 80  # one screen
    table = (res_dir / "thesis-vs-uvnav.md").read_text()
    row_md = "| path length Fig. 2.10 (Zhang) | 14.9 m | 15.2 m | reproduced | geometry chosen"
    assert row_md in table
    assert "1 reproduced" in table.split("| quantity")[0]  # the counts open the table
    # the same screen opens the table, as a text block
    assert table.split("```text\n", 1)[1].split("\n```", 1)[0].splitlines() == summary
    assert str(res_dir / "uvnav.sqlite") in result.stdout
    assert "2 figure file(s)" in result.stdout


def test_run_without_bench_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "uvnav.experiments", None)
    assert_one_line_error(invoke("run"), 1, "uvnav.experiments")


def test_report_calls_write_report(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from uvnav.bench.store import ResultsStore

    db = tmp_path / "uvnav.sqlite"
    ResultsStore(db).close()  # an empty store (an empty file is not one: test_cli_report_readonly)
    seen: list[tuple[Path, Path]] = []

    def write_report(
        db_path: Path, out_dir: Path, bench_dir: Path | None = None, **_kw: Any
    ) -> Path:
        seen.append((db_path, out_dir))
        if bench_dir is not None and not (bench_dir / "summary.json").exists():
            raise ValueError(f"{bench_dir}: benchmark file without the expected field 'targets'")
        return out_dir / "index.html"

    fake = types.ModuleType("uvnav.viz.report")
    fake.write_report = write_report  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "uvnav.viz.report", fake)
    out = tmp_path / "site"
    result = invoke("report", str(db), "--out", str(out))
    assert result.exit_code == 0, result.output
    assert seen == [(db, out)]
    assert "index.html" in result.stdout
    missing = invoke("report", str(db), "--bench", str(tmp_path / "nope"))
    assert missing.exit_code == 2 and "--bench must be a folder" in missing.output
    broken = invoke("report", str(db), "--bench", str(tmp_path))
    assert broken.exit_code == 2 and "expected field 'targets'" in broken.output
    assert "Traceback" not in broken.output


# ---------------------------------------------------------------------------- console script


def test_console_script_exit_codes_and_streams(free_scene: Path, tmp_path: Path) -> None:
    cmd = [sys.executable, "-m", "uvnav.cli"]
    good = subprocess.run(
        [*cmd, "simulate", str(free_scene), "--json"], capture_output=True, text=True, check=False
    )
    assert good.returncode == 0, good.stderr
    assert json.loads(good.stdout)["success"] is True
    bad_file = tmp_path / "bad.yaml"
    bad_file.write_text(FREE_SCENE.replace("v_max: 0.7", "v_max: -1"))
    bad = subprocess.run(
        [*cmd, "simulate", str(bad_file)], capture_output=True, text=True, check=False
    )
    assert bad.returncode == 2
    assert bad.stdout == ""
    assert bad.stderr == f"error: {bad_file}: robot.v_max: must be > 0 (got -1)\n"


def test_version() -> None:
    result = invoke("--version")
    assert result.exit_code == 0 and result.stdout.startswith("uvnav ")


@pytest.mark.parametrize("module", ["uvnav", "uvnav.cli"])
def test_python_dash_m_runs_the_console_script(module: str) -> None:
    out = subprocess.run(
        [sys.executable, "-m", module, "--version"], capture_output=True, text=True, check=False
    )
    assert out.returncode == 0 and out.stdout == invoke("--version").stdout
