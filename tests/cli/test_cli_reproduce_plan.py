"""``uvnav reproduce NAME --plan``: what the run would run, per campaign, and how much of it the
results database holds; it runs and writes nothing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from typer.testing import CliRunner

from uvnav.bench.store import ResultsStore
from uvnav.cli.app import app
from uvnav.experiments import ExperimentContext, plan_experiment, run_experiment

runner = CliRunner()


def _plan(res: Path, *args: str) -> dict[str, Any]:
    result = runner.invoke(app, ["reproduce", *args, "--plan", "--json", "--results", str(res)])
    assert result.exit_code == 0, result.output
    out: dict[str, Any] = json.loads(result.stdout)
    return out


def test_plan_keys_are_the_keys_the_run_stores(tmp_path: Path) -> None:
    res = tmp_path / "res"
    before = _plan(res, "ch4", "--seeds", "1")
    assert not res.exists()  # --plan creates no database (nor its folder)
    assert not before["database_exists"]
    assert all(c["stored"] == 0 for c in before["campaigns"])
    ctx = ExperimentContext(res, tmp_path / "rep", workers=1, seeds=1, progress=False)
    plans = plan_experiment("ch4", ctx)
    assert plans is not None
    run_experiment("ch4", ctx)
    with ResultsStore(res / "uvnav.sqlite", readonly=True) as store:
        assert sorted(c["name"] for c in store.campaigns()) == sorted(p.name for p in plans)
        for p in plans:
            cid = store.campaign_id(p.name)
            assert cid is not None
            assert {j.key for j in p.jobs} == store.done_keys(cid), p.name
    after = _plan(res, "ch4", "--seeds", "1")
    assert [c["name"] for c in after["campaigns"]] == [c["name"] for c in before["campaigns"]]
    for c in after["campaigns"]:
        assert c["stored"] == c["jobs"] > 0 and not c["stale"]
    # more seeds: the stored ones are counted, the new ones are not
    more = {c["name"]: c for c in _plan(res, "ch4", "--seeds", "2")["campaigns"]}
    assert more["ch4-random"]["stored"] * 2 == more["ch4-random"]["jobs"]


def test_plan_text_fits_80_columns_and_names_laws_scenes_and_stages(tmp_path: Path) -> None:
    res = tmp_path / "res"
    for name, seen in (
        ("regime", ["regime-map", "laws: ", "zhang2019-v1", "scenes: crowdnav-circle"]),
        ("ch5", ["ch5-random", "stages: data sets", "none yet"]),
        ("ch7", ["no campaign: it runs stages only", "stages: lattice counts"]),
    ):
        args = ["reproduce", name, "--plan", "--results", str(res)]
        if name != "ch7":
            args += ["--seeds", "1"]
        result = runner.invoke(app, args, env={"COLUMNS": "200"})
        assert result.exit_code == 0, result.output
        lines = result.stdout.splitlines()
        assert lines[0].startswith(f"{name} (quick): ")
        assert max(map(len, lines)) <= 80
        for fragment in seen:
            assert fragment in result.stdout, (name, fragment)
    assert not res.exists()


def test_plan_refusals_are_one_line(tmp_path: Path) -> None:
    res = tmp_path / "res"
    for args, fragment in (
        (["ch4", "--json"], "--json: only with --plan"),
        (["all", "--plan"], "--plan: name one experiment"),
        (["ch7", "--plan", "--seeds", "2"], "ch7 runs no random seeds"),
        (["nope", "--plan"], "nope"),
    ):
        result = runner.invoke(app, ["reproduce", *args, "--results", str(res)])
        assert result.exit_code == 2, result.output
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0]
    res.mkdir()
    (res / "uvnav.sqlite").write_text("not a database", encoding="utf-8")
    result = runner.invoke(app, ["reproduce", "ch4", "--plan", "--results", str(res)])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert len(result.stderr.strip().splitlines()) == 1
