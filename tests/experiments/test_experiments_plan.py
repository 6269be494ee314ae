"""``Experiment.plan``: what a run would run, built without running or writing anything."""

from __future__ import annotations

from pathlib import Path

import pytest

import uvnav.experiments.registry as registry
from uvnav.bench.store import FINGERPRINT_KEY, ResultsStore
from uvnav.experiments import (
    Experiment,
    ExperimentContext,
    ExperimentError,
    ExperimentRun,
    experiments,
    plan_experiment,
    plan_summary,
)


def _ctx(tmp_path: Path, **kw: object) -> ExperimentContext:
    return ExperimentContext(tmp_path / "res", tmp_path / "rep", progress=False, **kw)  # type: ignore[arg-type]


@pytest.mark.parametrize("name", list(experiments()))
def test_every_builtin_plans_without_writing(tmp_path: Path, name: str) -> None:
    exp = experiments()[name]
    ctx = _ctx(tmp_path, seeds=1 if exp.seeded else None)
    plans = plan_experiment(name, ctx)
    assert plans is not None
    assert not (tmp_path / "res").exists()
    names = [p.name for p in plans]
    assert len(names) == len(set(names))
    for p in plans:
        assert p.jobs and FINGERPRINT_KEY in p.config
        assert len({j.key for j in p.jobs}) == len(p.jobs)
    stages_only = name in ("ch6", "ch7")
    assert (plans == []) == stages_only
    assert bool(exp.stages) == (stages_only or name == "ch5")


def test_seeds_reach_the_plan(tmp_path: Path) -> None:
    one = {p.name: len(p.jobs) for p in plan_experiment("ch4", _ctx(tmp_path, seeds=1)) or []}
    two = {p.name: len(p.jobs) for p in plan_experiment("ch4", _ctx(tmp_path, seeds=2)) or []}
    assert one["ch4-thesis-scenes"] == two["ch4-thesis-scenes"]
    assert two["ch4-random"] == 2 * one["ch4-random"]
    starts = plan_experiment("ch4", _ctx(tmp_path, seeds=1, start_seed=5))
    assert starts is not None
    assert {j.seed for j in starts[1].jobs} == {5}


def test_an_unseeded_experiment_refuses_seeds_in_its_plan(tmp_path: Path) -> None:
    with pytest.raises(ExperimentError, match="runs no random seeds"):
        plan_experiment("beyond", _ctx(tmp_path, seeds=2))


def test_a_stored_campaign_of_other_code_is_shown_stale(tmp_path: Path) -> None:
    (tmp_path / "res").mkdir()
    with ResultsStore(tmp_path / "res" / "uvnav.sqlite") as store:
        store.campaign("ch4-random", {FINGERPRINT_KEY: "other code"})
    summary = plan_summary("ch4", _ctx(tmp_path, seeds=1))
    found = {c["name"]: c for c in summary["campaigns"]}
    assert summary["database_exists"]
    assert found["ch4-random"]["stale"] and found["ch4-random"]["stored"] == 0
    assert not found["ch4-noise"]["stale"]


def test_an_experiment_without_a_plan_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def run(ctx: ExperimentContext) -> ExperimentRun:
        raise AssertionError("a plan runs nothing")

    monkeypatch.setattr(registry, "BUILTINS", (Experiment("bare", "no plan", run),))
    monkeypatch.setattr(registry, "plugin_experiments", dict)
    assert plan_experiment("bare", _ctx(tmp_path)) is None
    summary = plan_summary("bare", _ctx(tmp_path))
    assert not summary["planned"] and summary["campaigns"] == []
