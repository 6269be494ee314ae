"""Experiments through the stage cache and their declared sizes: a stages-only run (Chapter 7)
and a mixed one (Chapter 6: stages and closed-loop episodes) interrupted at a random point resume
to the sections of an uninterrupted run; every built-in refuses, in one line, to resume over what
other code stored; every built-in declares its sizes."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import uvnav
from uvnav.bench.stages import STAGE_FILE, STAGES_DIR, StageCache, StaleStageError
from uvnav.bench.store import StaleCampaignError
from uvnav.experiments import ExperimentContext, Size, builtin_experiments, run_experiment
from uvnav.experiments.sections import SECTIONS_DIR

#: the tiniest size of every built-in that still stores what it refuses to mix with
TINY: dict[str, dict[str, Any]] = {
    "ch2": {"controllers": ("straight-v1",), "baselines": (), "n_random": 1, "n_crowd_seeds": 1},
    "crowds": {"laws": ("straight-v1",), "beyond": (), "cases": 1},
    "regime": {"laws": ("straight-v1",), "seeds": 1},
    "ch3": {"controllers": ("apf3d-v1",), "n_random": 1, "prediction_seeds": 1},
    "ch4": {"seeds": 1, "noise_seeds": 1, "hard_seeds": 1},
    "ch5": {
        "sizes": (), "n_seeds": 0, "literal_seeds": 0, "n_random": 1, "n_test": 30,
        "scenes": ["thesis-ch5-scene1"], "closed_loop_samples": 60,
    },
    "ch6": {
        "episodes": 2, "collect_steps": 60, "epochs": 1, "eval_seeds": [1000], "max_steps": 30,
        "dagger_rounds": 0,
    },
    "ch7": {
        "sizes": (150.0,), "radii": (50.0,), "plans": [("synthetic", 150.0, 50.0)],
        "coverage_kinds": ("flat",),
    },
    "beyond": {},
}  # fmt: skip
NEEDS = {"ch5": ("torch",), "ch6": ("torch", "gymnasium"), "regime": ("pyrvo",)}


@pytest.fixture
def tiny(monkeypatch: pytest.MonkeyPatch) -> Callable[[str, Path], ExperimentContext]:
    """``tiny(name, results)``: the context of the experiment's tiniest run (the parts no size
    parameter reaches are made small here)."""
    from uvnav.experiments import beyond as rb
    from uvnav.experiments import ch3 as r3
    from uvnav.experiments import ch7 as r7
    from uvnav.experiments import regime as rg

    fake = {"ar_rms": 1.0, "constant_rms": 2.0, "series": 1.0, "ratio": 0.5}
    monkeypatch.setattr(r3, "prediction_errors", lambda: fake)
    monkeypatch.setattr(r3, "prediction_study", lambda store, **kw: {})
    monkeypatch.setattr(r7, "CHECK_POINTS", 2000)
    monkeypatch.setattr(rb, "QUICK_LAWS", ("straight-v1",))
    monkeypatch.setattr(rb, "QUICK_SWAP", (("straight-v1", {}),))
    monkeypatch.setattr(rb, "replan_rows", lambda: [])
    cell = rg.regimes(densities=(4,), speed_ratios=(0.5,), visible=(False,), noises=(0.0,))
    TINY["regime"]["cells"] = cell[:1]

    def make(name: str, results: Path) -> ExperimentContext:
        for module in NEEDS.get(name, ()):
            pytest.importorskip(module)
        size = Size("tiny", params=TINY[name])
        return ExperimentContext(results, results / "report", workers=1, progress=False, size=size)

    return make


class Points:
    """The interruptible points of a run (a stage's build, an expert episode recorded, a closed
    loop driven): counts them, and raises :class:`KeyboardInterrupt` once at the ``at``-th."""

    def __init__(self, at: int | None = None) -> None:
        self.at, self.seen, self.fired = at, 0, False

    def tick(self) -> None:
        self.seen += 1
        if self.seen == self.at and not self.fired:
            self.fired = True
            raise KeyboardInterrupt


def _arm(monkeypatch: pytest.MonkeyPatch, points: Points) -> None:
    import uvnav.driving.collect as dc
    import uvnav.driving.pipeline as pl

    real_run, real_loop, real_episode = StageCache.run, pl.run_closed_loop, dc.collect_episode

    def run(self: StageCache, name: str, inputs: Any, build: Callable[[Path], Any]) -> Any:
        def ticked(work: Path) -> Any:
            points.tick()
            return build(work)

        return real_run(self, name, inputs, ticked)

    def ticking(real: Callable[..., Any]) -> Callable[..., Any]:
        def call(*args: Any, **kw: Any) -> Any:
            points.tick()
            return real(*args, **kw)

        return call

    monkeypatch.setattr(StageCache, "run", run)
    monkeypatch.setattr(pl, "run_closed_loop", ticking(real_loop))
    monkeypatch.setattr(dc, "collect_episode", ticking(real_episode))


def _finished(results: Path) -> list[Path]:
    """The stage folders (not the work folders and locks, whose names start with a dot)."""
    return [p for p in (results / STAGES_DIR).iterdir() if not p.name.startswith(".")]


def _section(results: Path, name: str) -> dict[str, Any]:
    return json.loads((results / SECTIONS_DIR / f"{name}.json").read_text())


@pytest.mark.parametrize(
    "name", ["ch7", pytest.param("ch6", marks=pytest.mark.slow)], ids=["stages", "mixed"]
)
def test_an_interrupted_run_resumes_to_the_uninterrupted_sections(
    name: str, tmp_path: Path, tiny: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    counted = Points()
    _arm(monkeypatch, counted)
    run_experiment(name, tiny(name, whole))
    assert counted.seen >= 3
    at = int(np.random.default_rng([33, len(name)]).integers(1, counted.seen + 1))
    points = Points(at)
    _arm(monkeypatch, points)
    with pytest.raises(KeyboardInterrupt):
        run_experiment(name, tiny(name, cut))
    finished = _finished(cut)
    assert all((p / STAGE_FILE).is_file() for p in finished)  # no half stage
    assert len(finished) < len(_finished(whole))
    run_experiment(name, tiny(name, cut))
    assert points.fired and _section(cut, name) == _section(whole, name), f"interrupted at {at}"
    names = [[s["name"] for s in StageCache(r, "").stored()] for r in (cut, whole)]
    assert names[0] == names[1]  # the same stages (a chained stage's key has its parent's id)


SLOW = {"ch5", "ch6"}


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in builtin_experiments()],
)
def test_a_run_over_results_of_other_code_is_refused_in_one_line(
    name: str, tmp_path: Path, tiny: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    run_experiment(name, tiny(name, tmp_path))
    again = run_experiment(name, tiny(name, tmp_path))  # the same code resumes
    assert again.sections
    monkeypatch.setattr(uvnav, "__version__", "0.0.0+other")  # every code fingerprint moves
    with pytest.raises(StaleCampaignError) as err:
        run_experiment(name, tiny(name, tmp_path))
    msg = str(err.value)
    assert "\n" not in msg and err.value.campaigns
    assert all(repr(c) in msg for c in err.value.campaigns), msg
    if isinstance(err.value, StaleStageError):  # a stage: --fresh remakes it
        assert "--fresh" in msg
        fresh = dataclasses.replace(tiny(name, tmp_path), fresh=True)
        assert run_experiment(name, fresh).sections


def test_every_builtin_declares_its_sizes_and_the_runner_passes_the_chosen_one() -> None:
    from uvnav.experiments import ch2, ch3, ch4, ch5, crowds, regime
    from uvnav.experiments.runner import _run_one

    known = builtin_experiments()
    for exp in known.values():
        assert set(exp.sizes) == {"quick", "full"}, exp.name
        assert all(s.runs and len(s.runs) <= 66 for s in exp.sizes.values()), exp.name
        assert (exp.sizes["quick"].seeds is not None) == exp.seeded, exp.name
    defaults = {"ch2": ch2, "ch3": ch3, "ch4": ch4, "ch5": ch5, "regime": regime}
    for name, module in defaults.items():
        seeds = (known[name].sizes["quick"].seeds, known[name].sizes["full"].seeds)
        quick, full = (
            ("QUICK_RANDOM", "FULL_RANDOM") if name == "ch5" else ("QUICK_SEEDS", "FULL_SEEDS")
        )
        assert seeds == (getattr(module, quick), getattr(module, full)), name
    cases = (known["crowds"].sizes["quick"].seeds, known["crowds"].sizes["full"].seeds)
    assert cases == (crowds.QUICK_CASES, crowds.FULL_CASES)
    seen: list[Any] = []
    exp = known["ch7"]
    probe = type(exp)(exp.name, exp.title, lambda ctx: seen.append(ctx.size), sizes=exp.sizes)
    for full in (False, True):
        with pytest.raises(AttributeError):  # the probe returns no run
            _run_one(probe, ExperimentContext(Path("r"), Path("p"), full=full))
    assert seen == [exp.sizes["quick"], exp.sizes["full"]]
