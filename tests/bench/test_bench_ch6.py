"""Chapter 6 pipeline: the tiny end-to-end reproduction and a DAgger round's data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("gymnasium")

from uvnav.bench.ch6_pipeline import dagger_collect
from uvnav.bench.reproduce_ch6 import reproduce_ch6
from uvnav.driving.dataset import read_log
from uvnav.learning import PilotNetConfig
from uvnav.learning.pilotnet import build_pilotnet


def test_tiny_reproduction_end_to_end(tmp_path: Path) -> None:
    s = reproduce_ch6(
        tmp_path,
        episodes=1,
        epochs=1,
        eval_seeds=[1000],
        max_steps=40,
        collect_steps=120,
        dagger_rounds=1,
        dagger_episodes=1,
        dagger_epochs=1,
    )
    assert s.record["n_frames"] == 90  # 30 rows x 3 cameras
    assert len(s.steering_train) + len(s.steering_val) == s.record["n_balanced"]
    assert set(s.closed_loop) == {"cnn-learned", "cnn-pi", "dagger1-pi", "expert"}
    # the DAgger rows go to a copy: data/ keeps the expert's 30 rows, the aggregate has more
    assert s.closed_loop["dagger1-pi"]["rows_added"] == 30  # 120 steps, one row every 4
    assert len(read_log(tmp_path / "data")) == 30
    assert len(read_log(tmp_path / "dagger_data")) == 60
    assert (tmp_path / "dagger1.safetensors").is_file()
    assert s.closed_loop["expert"]["return_vs_expert"] == pytest.approx(1.0)
    assert all(0.0 <= r["autonomy"] <= 1.0 for r in s.closed_loop.values())
    assert next(r["quantity"] for r in s.table) == "Ch6 frames before balancing"
    assert (tmp_path / "ch6.json").is_file() and s.model_path.is_file()
    names = [name for name, *_ in s.augment_examples]
    assert names == ["flip", "brightness", "zoom"]
    flip = s.augment_examples[0]
    assert np.array_equal(flip[2], flip[1][:, ::-1])  # the flip row is the mirror image
    from uvnav.viz.figures_ch6 import render_ch6

    figs = render_ch6(s, tmp_path / "figs")
    assert len(figs) == 6 and all(f.stat().st_size > 5000 for f in figs)


def test_dagger_round_appends_expert_labelled_rows(tmp_path: Path) -> None:
    import torch

    torch.manual_seed(0)
    model = build_pilotnet(PilotNetConfig()).eval()
    rows = dagger_collect(model, tmp_path, [4], round_id=1, max_steps=40, record_every=4)
    assert rows == 10
    log = read_log(tmp_path)
    assert len(log) == 10 and all("d1_00004" in p.name for p in log.center)
    assert np.all(np.abs(log.steering) <= 1.0) and np.all(np.abs(log.throttle) <= 1.0)
    # the first state is the start of the track, where the expert's label is near straight
    assert abs(log.steering[0]) < 0.3
