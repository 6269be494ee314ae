"""``uvnav reproduce NAME`` (one experiment, additive), ``uvnav reproduce --list`` and ``uvnav
forget`` (the only delete)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

import uvnav.experiments as experiments
from uvnav.bench.store import ResultsStore, StaleCampaignError
from uvnav.cli.app import app
from uvnav.experiments import (
    ExperimentContext,
    ExperimentRun,
    Reproduction,
    report_sections,
)
from uvnav.experiments.sections import SECTIONS_DIR, ChapterRenderers, ChapterSection, save_section

runner = CliRunner()


def _one_line_error(result: Any, *fragments: str) -> None:
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for f in fragments:
        assert f in lines[0]
    assert "Traceback" not in result.output


def test_reproduce_one_chapter_writes_its_section_beside_the_saved_ones(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    res, rep = tmp_path / "res", tmp_path / "rep"
    earlier = ChapterSection("ch4", "Chapter 4 — earlier", "run before", rows=[{"quantity": "q4"}])
    save_section(earlier, res / SECTIONS_DIR)
    calls: list[dict[str, Any]] = []

    def fake(name: str, ctx: ExperimentContext) -> Reproduction:
        calls.append({"name": name, "ctx": ctx})
        section = ChapterSection(
            "ch3", "Chapter 3 — now", "ran now", rows=[{"quantity": "q3", "measured": "42 %"}]
        )
        path = save_section(section, ctx.results_dir / SECTIONS_DIR)
        run = ExperimentRun([section], rows=section.rows)
        db = ctx.results_dir / "uvnav.sqlite"
        return Reproduction({name: run}, run.rows, [section], db, section_paths=[path])

    monkeypatch.setattr(experiments, "run_experiment", fake)
    result = runner.invoke(
        app,
        [
            *("reproduce", "ch3", "--seeds", "2", "--start-seed", "7", "--workers", "1", "--fresh"),
            *("--results", str(res), "--report", str(rep)),
        ],
        env={"COLUMNS": "200"},
    )
    assert result.exit_code == 0, result.output
    (call,) = calls
    ctx = call["ctx"]
    assert (call["name"], ctx.seeds, ctx.start_seed, ctx.workers) == ("ch3", 2, 7, 1)
    assert (ctx.results_dir, ctx.report_dir) == (res, rep)
    assert ctx.full is False and ctx.fresh is True and callable(ctx.render)
    assert isinstance(ctx.renderers, ChapterRenderers) and ctx.renderers.ch3 is not None
    html = (rep / "index.html").read_text(encoding="utf-8")
    # the chapter just run and the one saved by an earlier run, in chapter order
    assert html.index('id="section-ch3"') < html.index('id="section-ch4"')
    assert "42 %" in html and "q4" in html
    assert "42 %" in result.stdout and f"wrote {rep / 'index.html'}" in result.stdout


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["ch7", "--seeds", "2"], ["ch7 runs no random seeds"]),
        (["beyond", "--start-seed", "1"], ["beyond runs no random seeds"]),
        (["ch9"], ["unknown experiment 'ch9'", "beyond", "regime"]),
        (["all", "--seeds", "3"], ["reproduce all", "--seeds"]),
        ([], ["name an experiment", "--list"]),
        (["--list", "ch2"], ["--list takes no experiment name"]),
    ],
)
def test_reproduce_bad_options_are_one_line_errors(
    tmp_path: Path, args: list[str], fragments: list[str]
) -> None:
    res = tmp_path / "res"
    result = runner.invoke(app, ["reproduce", *args, "--results", str(res)])
    _one_line_error(result, *fragments)
    assert not (res / "uvnav.sqlite").exists()


def test_a_stale_campaign_is_refused_in_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def stale(*_a: Any, **_k: Any) -> None:
        raise StaleCampaignError(
            tmp_path / "uvnav.sqlite", ["ch2-random"], "was stored by other code"
        )

    monkeypatch.setattr(experiments, "run_experiment", stale)
    result = runner.invoke(app, ["reproduce", "ch2", "--results", str(tmp_path)])
    _one_line_error(result, "'ch2-random'", "uvnav forget", "ch2-random' or use another")


def test_reproduce_all_is_uvnav_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from uvnav.cli import reproduce as cli_reproduce

    seen: list[dict[str, Any]] = []
    monkeypatch.setattr(cli_reproduce, "run_cmd", lambda **kw: seen.append(kw))
    result = runner.invoke(app, ["reproduce", "all", "--full", "--results", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert seen == [
        {"full": True, "workers": 2, "results": tmp_path, "report": Path("report"), "fresh": False}
    ]


def test_list_shows_every_experiment_on_80_columns() -> None:
    result = runner.invoke(app, ["reproduce", "--list"])
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0].split() == ["name", "seeded", "title"]
    heads = [line for line in lines[1:] if not line.startswith(" ")]
    rows = {line.split()[0]: line.split()[1] for line in heads}
    assert list(rows) == ["ch2", "crowds", "regime", "ch3", "ch4", "ch5", "ch6", "ch7", "beyond"]
    assert rows["ch3"] == "yes" and rows["ch7"] == "no"
    assert any("Chapter 7: UAV reconnaissance" in line for line in lines)
    sizes = [line.split()[0] for line in lines[1:] if line.startswith(" ")]
    assert sizes == ["quick:", "full:"] * len(rows)  # every experiment's declared sizes
    assert any("2 expert episodes of 500 steps" in line for line in lines)  # ch6's quick size
    assert max(len(line) for line in lines) <= 80


def test_the_old_entry_points_are_gone() -> None:
    for args in (["ch4", "run"], ["sonar", "reproduce"]):
        result = runner.invoke(app, args)
        assert result.exit_code == 2, (args, result.output)
    import uvnav.experiments.ch3 as r3

    assert not hasattr(r3, "main")


def test_forget_removes_only_the_named_campaigns(tmp_path: Path) -> None:
    db = tmp_path / "uvnav.sqlite"
    with ResultsStore(db) as store:
        for name in ("a", "b"):
            cid = store.campaign(name, {})
            store.add_episode(cid, scenario="s", controller="c", seed=0, status="success")
    result = runner.invoke(app, ["forget", str(db), "a"])
    assert result.exit_code == 0, result.output
    assert "removed campaign 'a' (1 episode(s))" in result.stdout
    with ResultsStore(db) as store:
        assert [c["name"] for c in store.campaigns()] == ["b"] and store.count("b") == 1
    _one_line_error(runner.invoke(app, ["forget", str(db), "zzz"]), "no campaign 'zzz'", "b")
    with ResultsStore(db) as store:
        assert store.count("b") == 1
    _one_line_error(runner.invoke(app, ["forget", str(tmp_path / "no.sqlite"), "b"]), "no such")


def test_report_rebuilds_the_chapter_sections_it_can(tmp_path: Path) -> None:
    """``uvnav report DB`` of a ``uvnav run`` database keeps the chapters: saved sections as
    they are, Ch. 2 rebuilt from its stored rows, the rest named with the command to rerun."""
    from uvnav.experiments import ch2 as rp

    db = tmp_path / "uvnav.sqlite"
    with ResultsStore(db) as store:
        cid = store.campaign(
            rp.SCENES_CAMPAIGN,
            {"scenes": [rp.COMPARISON_SCENE], "controllers": ["zhang2019-v1"], "fingerprint": "x"},
        )
        store.add_episode(
            cid,
            scenario=rp.COMPARISON_SCENE,
            controller="zhang2019-v1",
            seed=0,
            status="success",
            metrics={"path_length": 15.0, "min_clearance": 0.5},
        )
        store.campaign("ch3-random", {})
    (tmp_path / "ch7").mkdir()
    save_section(
        ChapterSection("beyond", "Beyond the thesis", "saved", rows=[{"quantity": "swap"}]),
        tmp_path / SECTIONS_DIR,
    )
    before = db.read_bytes()
    secs = report_sections(db)
    assert [s.key for s in secs] == ["ch2", "ch3", "ch7", "beyond"]
    ch2 = secs[0]
    assert any("Fig. 2.10 path length, zhang2019-v1" in r["quantity"] for r in ch2.rows)
    assert "uvnav reproduce ch3" in secs[1].notes[0] and "uvnav reproduce ch7" in secs[2].notes[0]
    out = tmp_path / "site"
    result = runner.invoke(app, ["report", str(db), "--out", str(out)])
    assert result.exit_code == 0, result.output
    html = (out / "index.html").read_text(encoding="utf-8")
    assert "No reproduction table was given" not in html
    for key in ("ch2", "ch3", "ch7", "beyond"):
        assert f'id="section-{key}"' in html
    assert "15.00 m" in html or "15.0" in html
    assert db.read_bytes() == before  # the report only reads


def test_reproduce_crowds_runs_the_crowd_section(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from uvnav.experiments import crowds as rc

    # two laws instead of every 2D law (the rest of the run is real: 2 cases per scene)
    monkeypatch.setattr(rc, "crowd_laws", lambda: (["orca-holonomic-v1", "zhang2019-v1"], []))
    res, rep = tmp_path / "res", tmp_path / "rep"
    args = ["reproduce", "crowds", "--seeds", "2", "--workers", "1"]
    result = runner.invoke(
        app, [*args, "--results", str(res), "--report", str(rep)], env={"COLUMNS": "250"}
    )
    assert result.exit_code == 0, result.output
    assert "CrowdNav circle crossing" in result.stdout and "refused (2/2" in result.stdout
    html = (rep / "index.html").read_text(encoding="utf-8")
    assert 'id="section-crowds"' in html and "0.43" in html
    with ResultsStore(res / "uvnav.sqlite") as store:
        assert store.count(rc.CAMPAIGN) == 2 * 2 * 2
    # a second call adds nothing
    again = runner.invoke(app, [*args, "--results", str(res), "--report", str(rep)])
    assert again.exit_code == 0, again.output
    with ResultsStore(res / "uvnav.sqlite") as store:
        assert store.count(rc.CAMPAIGN) == 2 * 2 * 2
