"""The experiments' registry and runner: the built-ins in report order, unknown names and
shadowing plug-ins refused in one line, ``run_all`` in order with one page over every section."""

from __future__ import annotations

import json
from collections.abc import Iterator
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

import uvnav.core
from uvnav.cli.app import app
from uvnav.experiments import (
    EXPERIMENT_GROUP,
    Experiment,
    ExperimentContext,
    ExperimentError,
    ExperimentRun,
    builtin_experiments,
    experiments,
    get_experiment,
    registry,
    run_all,
    run_experiment,
    saved_sections,
)
from uvnav.experiments.sections import SECTION_ORDER, SECTIONS_DIR, ChapterSection, save_section

PLUGIN = Path(__file__).resolve().parents[1] / "plugins" / "dummy_experiment"


@pytest.fixture
def plugins(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[EntryPoint]]:
    """Entry points of the experiments' group as a test writes them (the dummy plug-in's module
    on the path); every other group has none while the test runs."""
    found: list[EntryPoint] = []
    monkeypatch.syspath_prepend(str(PLUGIN))
    monkeypatch.setattr(
        uvnav.core, "entry_points", lambda group: found if group == EXPERIMENT_GROUP else []
    )
    uvnav.core.load_plugins.cache_clear()
    yield found
    uvnav.core.load_plugins.cache_clear()


def _ep(name: str, value: str) -> EntryPoint:
    return EntryPoint(name, value, EXPERIMENT_GROUP)


def test_the_builtins_in_report_order() -> None:
    known = builtin_experiments()
    assert tuple(known) == SECTION_ORDER  # the saved sections load in the registry's order
    assert [e.order for e in known.values()] == sorted(e.order for e in known.values())
    assert {n for n, e in known.items() if e.seeded} == {
        "ch2", "ch3", "ch4", "ch5", "crowds", "regime",
    }  # fmt: skip
    assert all(e.title and "\n" not in e.title and len(e.title) <= 64 for e in known.values())


def test_an_unknown_name_is_refused_with_the_known_ones() -> None:
    with pytest.raises(ExperimentError) as err:
        get_experiment("ch9")
    msg = str(err.value)
    assert msg.startswith("unknown experiment 'ch9'; known: ch2, crowds, regime, ch3")
    assert "beyond, or all" in msg and "\n" not in msg


@pytest.mark.parametrize("name", ["ch2", "all"])
def test_a_plugin_that_shadows_a_builtin_is_refused_in_one_line(
    plugins: list[EntryPoint], name: str
) -> None:
    plugins.append(_ep(name, "dummy_experiment:SHADOW"))
    with pytest.raises(ExperimentError) as err:
        experiments()
    msg = str(err.value)
    assert f"experiment {name!r} of dummy_experiment:SHADOW is already registered" in msg
    assert "\n" not in msg
    result = CliRunner().invoke(app, ["reproduce", "--list"])
    assert result.exit_code == 2, result.output
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith("error: ") and f"{name!r}" in line


@pytest.mark.parametrize(
    ("value", "fragment"),
    [
        ("dummy_experiment:LAW", "is a str, not a uvnav Experiment"),
        ("dummy_experiment:SHADOW", "is named 'ch2'; the entry point must be its name"),
        ("no_such_module_here:X", "failed: ModuleNotFoundError"),
    ],
)
def test_a_broken_plugin_is_refused_in_one_line(
    plugins: list[EntryPoint], value: str, fragment: str
) -> None:
    plugins.append(_ep("mine", value))
    with pytest.raises(ExperimentError, match=fragment) as err:
        experiments()
    assert "\n" not in str(err.value)


def test_a_plugin_joins_the_registry_in_its_order(plugins: list[EntryPoint]) -> None:
    plugins.append(_ep("dummy", "dummy_experiment:DUMMY"))
    known = experiments()
    assert list(known)[-3:] == ["ch7", "dummy", "beyond"]  # order 85: between 80 and 90
    assert known["dummy"].seeded and get_experiment("dummy") is known["dummy"]


# ------------------------------------------------------------------------------ the runner


def _fake(name: str, order: int, log: list[str], *, seeded: bool = False) -> Experiment:
    def run(ctx: ExperimentContext) -> ExperimentRun:
        log.append(f"{name} seeds={ctx.seeds} start={ctx.start_seed}")
        row = {"quantity": f"q-{name}", "measured": name}
        return ExperimentRun([ChapterSection(name, name.upper(), "")], rows=[row])

    return Experiment(name, f"the {name} experiment", run, seeded=seeded, order=order)


def test_run_all_runs_every_experiment_in_order_and_writes_one_page(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    log: list[str] = []
    pages: list[tuple[list[str], list[str]]] = []
    page = tmp_path / "rep" / "index.html"

    def first(ctx: ExperimentContext) -> ExperimentRun:
        log.append(f"first seeds={ctx.seeds} start={ctx.start_seed}")
        section = ChapterSection("first", "First", "")

        def report(sections: list[ChapterSection], table: list[dict[str, str]]) -> Any:
            pages.append(([s.key for s in sections], [r["quantity"] for r in table]))
            section.notes.append("drawn with the page")  # saved after the page
            return page, [tmp_path / "fig.png"]

        return ExperimentRun([section], rows=[{"quantity": "q-first"}], report=report)

    fakes = (
        _fake("last", 90, log),
        Experiment("first", "the first", first, seeded=True, order=10),
        _fake("middle", 50, log, seeded=True),
    )
    monkeypatch.setattr(registry, "BUILTINS", fakes)
    monkeypatch.setattr(registry, "plugin_experiments", lambda: {"plug": _fake("plug", 60, log)})
    ctx = ExperimentContext(tmp_path / "res", tmp_path / "rep", seeds=3, start_seed=2)
    out = run_all(ctx)
    assert log == [
        "first seeds=3 start=2", "middle seeds=3 start=2",
        "plug seeds=None start=0", "last seeds=None start=0",
    ]  # fmt: skip
    assert pages == [
        (["first", "middle", "plug", "last"], ["q-first", "q-middle", "q-plug", "q-last"])
    ]
    assert out.report_path == page and out.figures == [tmp_path / "fig.png"]
    assert [s.key for s in out.sections] == ["first", "middle", "plug", "last"]
    assert [s.key for s in saved_sections(ctx.results_dir)] == ["first", "middle", "plug", "last"]
    saved = json.loads((ctx.results_dir / SECTIONS_DIR / "first.json").read_text())
    assert saved["notes"] == ["drawn with the page"]
    assert list(run_all(ctx, names=("last", "middle")).runs) == ["middle", "last"]
    with pytest.raises(ExperimentError, match="unknown experiment 'nope'"):
        run_all(ctx, names=("nope",))


def test_run_experiment_pages_its_section_before_the_saved_ones(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    log: list[str] = []
    pages: list[list[str]] = []

    def paged(ctx: ExperimentContext) -> ExperimentRun:
        def report(sections: list[ChapterSection], table: list[dict[str, str]]) -> Any:
            pages.append([s.key for s in sections] + [r["quantity"] for r in table])
            return None, []

        rows = [{"quantity": "q-paged"}]
        return ExperimentRun([ChapterSection("paged", "P", "")], rows=rows, report=report)

    def wrong(ctx: ExperimentContext) -> ExperimentRun:
        return ExperimentRun([ChapterSection("other", "O", "")])

    fakes = (
        _fake("early", 10, log),
        Experiment("paged", "paged", paged, order=20),
        Experiment("wrong", "wrong", wrong, order=30),
    )
    monkeypatch.setattr(registry, "BUILTINS", fakes)
    monkeypatch.setattr(registry, "plugin_experiments", dict)
    res = tmp_path / "res"
    save_section(ChapterSection("early", "E", "", rows=[{"quantity": "q-early"}]), res / "sections")
    out = run_experiment("paged", ExperimentContext(res, tmp_path / "rep"))
    assert pages == [["paged", "early", "q-paged", "q-early"]]
    assert out.table == [{"quantity": "q-paged"}] and out.report_path is None
    with pytest.raises(ExperimentError, match="returned section 'other'; its sections are wrong"):
        run_experiment("wrong", ExperimentContext(res, tmp_path / "rep"))
    with pytest.raises(ExperimentError, match="early runs no random seeds"):
        run_experiment("early", ExperimentContext(res, tmp_path / "rep", seeds=1))
