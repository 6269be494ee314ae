"""Chapter 3, what prediction buys (issue 21): AR vs constant velocity vs the oracle."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import uvnav.scenarios.episodes as episodes
from uvnav.bench.campaign import run_job
from uvnav.bench.store import ResultsStore
from uvnav.experiments import ch3 as r3
from uvnav.experiments.sections import ch3_section


def test_the_default_familys_one_step_figure_is_unchanged() -> None:
    """horizon_errors' one-step errors on random-ch3 (and so prediction_errors') are those of
    one_step_errors on every body's velocity series, scene by scene."""
    from uvnav.obstacles.motion3d import ObstacleState3D
    from uvnav.prediction.autoregressive import ARPredictor, one_step_errors, rms
    from uvnav.scenarios.generators3d import random_ch3_scenario

    e_ar: list[np.ndarray] = []
    e_cv: list[np.ndarray] = []
    seed = 0
    while len(e_ar) < 3:
        for ob in random_ch3_scenario(seed).build(seed).obstacles:
            st = ObstacleState3D(np.zeros(3))
            series = np.array([ob.motion.rates(float(k), st)[0] for k in range(40)])
            a, c = one_step_errors(series, ARPredictor(dim=3, max_lag=3))
            e_ar.append(a)
            e_cv.append(c)
        seed += 1
    old = {"ar_rms": rms(np.concatenate(e_ar)), "constant_rms": rms(np.concatenate(e_cv))}
    assert r3.prediction_errors(n_series=3, length=40) == {
        **old,
        "series": float(len(e_ar)),
        "ratio": old["ar_rms"] / old["constant_rms"],
    }
    new = r3.horizon_errors("ar", n_series=3, length=40)
    assert new["v1_ar"] == old["ar_rms"] and new["v1_cv"] == old["constant_rms"]
    assert new["series"] == len(e_ar) and new["p1_ar"] == new["p1_cv"] == 0.0


def test_ar_beats_constant_velocity_on_the_periodic_family() -> None:
    e = r3.horizon_errors("periodic", n_series=4, length=60)
    for k in r3.HORIZONS:
        assert e[f"v{k}_ar"] < 0.8 * e[f"v{k}_cv"], (k, e)
    k = max(r3.HORIZONS)
    assert e[f"p{k}_ar"] < e[f"p{k}_cv"]


def _study(ar: float, cv: float, orc: float, n: int = 20) -> dict[str, Any]:
    errors = {fam: {"v1_ar": 0.03, "v1_cv": 0.06, "v3_ar": 0.07, "v3_cv": 0.15, "p3_ar": 0.08,
                    "p3_cv": 0.17, "series": 23.0} for fam in r3.PREDICTION_FAMILIES}  # fmt: skip
    closed = {
        f"{fam}|{arm}": {"n": float(n), "success": s, "collision": 1 - s, "min_clearance": 0.4}
        for fam in r3.PREDICTION_FAMILIES
        for arm, s in zip(r3.PREDICTION_ARMS, (ar, cv, orc), strict=True)
    }
    usage = {fam: {"decisions": 100.0, "ar_share": 0.1} for fam in r3.PREDICTION_FAMILIES}
    return {"errors": errors, "closed_loop": closed, "usage": usage, "seeds": n}


def test_the_finding_is_one_sentence_from_the_numbers() -> None:
    same = r3.prediction_finding(_study(0.95, 0.95, 1.0))
    assert same.count(". ") == 0 and same.endswith(".")
    assert "is 50% of constant velocity's on random-ch3 and 50% on random-ch3-periodic" in same
    assert "95.0% / 95.0% / 100.0% on random-ch3 and" in same
    assert "buys nothing measurable" in same and "making 10% and 10% of its M2" in same
    assert "raises the closed-loop success rate" in r3.prediction_finding(_study(1.0, 0.9, 1.0))
    assert "does not consistently help" in r3.prediction_finding(_study(0.9, 1.0, 1.0))
    rows = r3.prediction_rows(_study(0.95, 0.9, 1.0))
    succ = [r for r in rows if "success by prediction" in r["quantity"]]
    assert len(succ) == len(r3.PREDICTION_FAMILIES)
    assert succ[0]["measured"] == (
        "AR prediction 95.0% / constant velocity 90.0% / oracle 100.0% of 20"
    )


def test_the_study_stores_three_arms_per_family_and_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(r3, "horizon_errors", lambda motion: {"v1_ar": 1.0, "v1_cv": 2.0})
    monkeypatch.setattr(r3, "ar_usage", lambda fam, seeds: {"decisions": 1.0, "ar_share": 1.0})
    calls: list[tuple[str, str]] = []
    real_run_scene = episodes.run_scene

    def run_scene(resolved: Any, *args: Any, **kw: Any) -> Any:
        out = real_run_scene(resolved, *args, **kw)
        calls.append((resolved.spec, json.dumps(out.params, sort_keys=True)))
        return out

    monkeypatch.setattr(episodes, "run_scene", run_scene)
    with ResultsStore(tmp_path / "db.sqlite") as store:
        study = r3.prediction_study(store, n_seeds=1, start_seed=2)
        # each family's scene 2 with each arm's law parameters: AR, constant velocity, oracle
        arms = ['{"prediction": "last"}', "{}", '{"oracle": true}']
        assert sorted(calls) == sorted((f"{f}:2", a) for f in r3.PREDICTION_FAMILIES for a in arms)
        assert set(study["closed_loop"]) == {
            f"{f}|{a}" for f in r3.PREDICTION_FAMILIES for a in r3.PREDICTION_ARMS
        }
        assert all(r["n"] == 1.0 for r in study["closed_loop"].values())
        assert all(0.0 <= u["ar_share"] <= 1.0 for u in study["usage"].values())
        calls.clear()
        again = r3.prediction_study(store, n_seeds=1, start_seed=2)  # stored: nothing runs
        assert calls == [] and again["closed_loop"] == study["closed_loop"]


def test_constant_velocity_arm_uses_the_sensed_rates() -> None:
    """The "constant" arm is zhang2020-3d-v1 with prediction="last" on estimated rates: on the
    periodic family its episode differs from the AR arm's, and both are deterministic."""
    job = r3.ch3_job("random-ch3-periodic:0", r3.PREDICTION_LAW, 0, "constant", record=True)
    a, b = run_job(job), run_job(job)
    assert a.metrics is not None and b.metrics is not None
    assert a.metrics["min_clearance"] == b.metrics["min_clearance"]
    assert a.metrics["path_length"] == b.metrics["path_length"]
    ar = run_job(
        r3.ch3_job("random-ch3-periodic:0", r3.PREDICTION_LAW, 0, "predicted", record=True)
    )
    assert ar.result is not None and a.result is not None and ar.metrics is not None
    assert ar.metrics["min_clearance"] != a.metrics["min_clearance"]


def test_the_section_shows_the_rows_and_the_sentence() -> None:
    study = _study(0.95, 0.95, 1.0)
    summary = r3.Ch3Summary(
        table=r3.prediction_rows(study), db_path=Path("x"), failures=[], prediction={},
        study=study, finding=r3.prediction_finding(study),
    )  # fmt: skip
    sec = ch3_section(summary, full=False)
    assert sec.notes[0] == summary.finding
    assert "random-ch3-periodic" in sec.intro and "20 seeds" in sec.intro
    assert any("success by prediction" in r["quantity"] for r in sec.rows)
