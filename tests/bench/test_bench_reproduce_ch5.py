"""Chapter 5 reproduction (small settings): measured rows, JSON, checkpoint and figures."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("torch")

from uvnav.bench.reproduce_ch5 import make_locator, reproduce_ch5
from uvnav.learning.bpnn import load_checkpoint
from uvnav.viz.figures_ch5 import render_ch5


@pytest.mark.slow
def test_small_reproduction_writes_measured_table_and_figures(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import uvnav.viz.figures_ch5 as f5

    monkeypatch.setattr(f5, "ANIMATION_FRAMES", 3)  # the GIF's content is tested in tests/viz
    s = reproduce_ch5(
        tmp_path / "results",
        sizes=(50,),
        n_seeds=1,
        n_random=0,
        n_test=30,
        scenes=["thesis-ch5-scene1"],
        noises=(0.0,),
        closed_loop_samples=60,
        progress=False,
        render=render_ch5,
        report_dir=tmp_path / "report",
    )
    data = json.loads((tmp_path / "results" / "ch5.json").read_text())
    # plain, residual and residual-Huber at 50, and the closed-loop network
    assert [r["variant"] for r in data["learning"]] == [
        "plain",
        "residual",
        "residual-huber",
        "residual",
    ]
    assert {r["locator"] for r in data["closed_loop"]} == {"geometric", "network", "oracle"}
    assert len(data["closed_loop"]) == 3  # 1 thesis scene x 3 locators
    quantities = [r["quantity"] for r in s.table]
    assert any("50 samples: distance error, test group" in q for q in quantities)
    assert any("thesis scenes reached" in q for q in quantities)
    row = next(r for r in s.table if "(plain) 50 samples: distance error" in r["quantity"])
    assert row["thesis"] == "[-1.688, 1.861]"
    lo = data["learning"][0]["test_group"]["network"]["distance"]["lo"]
    assert f"{lo:.4g}" in row["measured"]
    model = load_checkpoint(tmp_path / "results" / "ch5_bpnn")
    assert model.config.residual
    assert make_locator("network", tmp_path / "results" / "ch5_bpnn.safetensors") is not None
    names = {p.name for p in s.figures}
    assert {"ch5_array.png", "ch5_learning_curve.png"} <= names
    assert any(n.startswith("ch5_traj_thesis-ch5-scene1") for n in names)
    assert all(p.stat().st_size > 5000 for p in s.figures)
    assert "ch5_anim_thesis-ch5-scene1_network.gif" in names  # the animated run
    from uvnav.bench.reproduce_ch5 import SCENES_CAMPAIGN, stored_rows
    from uvnav.bench.store import ResultsStore

    with ResultsStore(tmp_path / "results" / "uvnav.sqlite") as store:
        stored = stored_rows(store, SCENES_CAMPAIGN)
    assert sorted(r["locator"] for r in stored) == ["geometric", "network", "oracle"]
    assert [r["status"] for r in stored] == [r["status"] for r in data["closed_loop"]]
    with pytest.raises(ValueError, match="unknown locator"):
        make_locator("psychic")
