"""Chapter 6's reproduction: the tiny end-to-end run, its stages and resume, its notes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("gymnasium")

from uvnav.driving.dataset import read_log
from uvnav.experiments.ch6 import reproduce_ch6


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
        head="target_speed",  # the thesis's throttle head: the chain test below
    )
    assert s.record["n_frames"] == 90  # 30 rows x 3 cameras
    assert len(s.steering_train) + len(s.steering_val) == s.record["n_balanced"]
    # the target-speed head drives DAgger with its own learned-speed throttle
    assert set(s.closed_loop) == {"cnn-learned-speed", "cnn-pi", "dagger1-learned-speed", "expert"}
    assert s.record["second_output"] == "target_speed" and s.record["val_target_speed_rmse"]
    two = next(r for r in s.table if r["quantity"].startswith("Ch6 validation MSE (steering +"))
    assert "target speed RMSE" in two["note"]
    stages = {r["name"]: tmp_path / "stages" / r["key"] for r in _stored(tmp_path)}
    assert not list(tmp_path.rglob("*.train-state.safetensors"))  # removed once models are saved
    # every closed-loop row keeps each track's metrics, and the means are theirs
    for name, row in s.closed_loop.items():
        per = s.tracks[name]
        assert [t["seed"] for t in per] == [1000]
        assert row["return"] == pytest.approx(np.mean([t["return"] for t in per]))
    # the steering row compares eq. (6.1) with the thesis, by camera, with exact side labels
    steer_row = next(r for r in s.table if "MSE of the steering, eq. (6.1)" in r["quantity"])
    assert steer_row["measured"] == f"{s.record['val_steering_mse'][-1]:.4f}"
    assert "side-image labels: exact" in steer_row["note"]
    assert set(s.record["val_steering_mse_by_camera"]) <= {"centre", "left", "right"}
    # the DAgger rows go to a copy: data/ keeps the expert's 30 rows, the aggregate has more
    assert s.closed_loop["dagger1-learned-speed"]["rows_added"] == 30  # 120 steps, every 4th
    assert len(read_log(stages["ch6-data"] / "data")) == 30
    assert len(read_log(stages["ch6-dagger1"] / "data")) == 60
    assert (stages["ch6-dagger1"] / "dagger1.safetensors").is_file()
    assert s.model_path == stages["ch6-train"] / "model.safetensors"
    assert s.closed_loop["expert"]["return_vs_expert"] == pytest.approx(1.0)
    assert all(0.0 <= r["autonomy"] <= 1.0 for r in s.closed_loop.values())
    assert next(r["quantity"] for r in s.table).startswith("Ch6 frames before balancing")
    assert all("[quick size]" in r["quantity"] for r in s.table)
    steer = next(r for r in s.table if "steering over all frames" in r["quantity"])
    assert steer["thesis"] == "-1 / 1 / -0.009 / 0.204"
    lo, hi, mean, std = (float(x) for x in steer["measured"].split(" / "))
    assert lo == pytest.approx(s.steering_all.min(), abs=0.005) and lo <= mean <= hi and std >= 0
    assert steer["note"].startswith(f"{s.steering_all.size} frames")
    assert (tmp_path / "ch6.json").is_file() and s.model_path.is_file()
    names = [name for name, *_ in s.augment_examples]
    assert names == ["flip", "brightness", "zoom"]
    flip = s.augment_examples[0]
    assert np.array_equal(flip[2], flip[1][:, ::-1])  # the flip row is the mirror image
    from uvnav.viz.figures_ch6 import render_ch6

    figs = render_ch6(s, tmp_path / "figs")
    assert len(figs) == 6 and all(f.stat().st_size > 5000 for f in figs)
    # the report section of a quick run: every figure with its thesis caption, the table
    from uvnav.experiments.sections import ch6_section

    s.figures = figs
    sec = ch6_section(s, full=False)
    captions = " ".join(f.caption for f in sec.figures)
    for fig in ("6.1", "6.4", "6.5", "6.6", "6.7", "6.8"):
        assert f"Fig. {fig}" in captions
    assert [f.path for f in sec.figures] == figs
    quantities = [r["quantity"] for r in sec.rows]
    assert sum("closed loop" in q for q in quantities) == 4  # 3 network rows + the expert
    assert "Quick size" in sec.notes[0] and "1 held-out track of up to 40 steps" in sec.intro


def _stored(folder: Path) -> list[dict]:
    from uvnav.bench.stages import StageCache

    return StageCache(folder, "").stored()


def test_full_chain_stages_and_resume(tmp_path: Path) -> None:
    """The thesis head's chain: pedal head, PI, readout, one DAgger round with learned-speed,
    expert — each stage stored as it finishes and reused on a rerun."""
    import json
    import shutil

    from uvnav.bench.stages import STAGE_FILE, StaleStageError

    kw: dict = {
        "episodes": 1,
        "epochs": 1,
        "eval_seeds": [1000],
        "max_steps": 30,
        "collect_steps": 80,
        "dagger_rounds": 1,
        "dagger_episodes": 1,
        "dagger_epochs": 1,
    }
    s = reproduce_ch6(tmp_path, **kw)
    chain = ["cnn-learned", "cnn-pi", "cnn-learned-speed", "dagger1-learned-speed", "expert"]
    assert list(s.closed_loop) == chain
    assert s.reused == []
    names = ["ch6-data", "ch6-train", "ch6-readout", "ch6-dagger1", *(f"ch6-{c}" for c in chain)]
    stages = {r["name"]: tmp_path / "stages" / r["key"] for r in _stored(tmp_path)}
    assert sorted(stages) == sorted(names)
    for name, f in (("train", "model"), ("readout", "readout"), ("dagger1", "dagger1")):
        assert (stages[f"ch6-{name}"] / f"{f}.safetensors").is_file()
    assert s.stage_records["readout"]["second_output"] == "target_speed"
    assert s.stage_records["dagger1"]["second_output"] == "target_speed"
    assert any("target-speed readout" in r["quantity"] for r in s.table)
    for r in s.closed_loop.values():
        assert r["interventions_per_lap"] >= 0.0
    # a rerun with the same settings reuses every stage and reports the same numbers
    before = {p: p.stat().st_mtime_ns for p in (tmp_path / "stages").rglob("*.safetensors")}
    s2 = reproduce_ch6(tmp_path, **kw)
    assert sorted(s2.reused) == sorted(names)
    assert {p: p.stat().st_mtime_ns for p in (tmp_path / "stages").rglob("*.safetensors")} == (
        before
    )
    assert s2.closed_loop == s.closed_loop and s2.table == s.table
    assert len(read_log(stages["ch6-dagger1"] / "data")) == 20 + 20  # not driven again
    # an interrupted run: the DAgger round and a later closed loop were not stored; the round
    # is driven again from the expert's data, the stages before it are reused
    shutil.rmtree(stages["ch6-dagger1"])
    shutil.rmtree(stages["ch6-expert"])
    s3 = reproduce_ch6(tmp_path, **kw)
    assert sorted(s3.reused) == sorted(names[:3] + [f"ch6-{c}" for c in chain[:3]])
    again = {r["name"]: tmp_path / "stages" / r["key"] for r in _stored(tmp_path)}
    assert len(read_log(again["ch6-dagger1"] / "data")) == 40  # copied afresh, driven once
    assert json.loads((again["ch6-dagger1"] / STAGE_FILE).read_text())["value"]["rows_after"] == 40
    # other settings (more epochs) make training and every stage built on it anew; without
    # the readout, DAgger drives with the PI throttle
    s4 = reproduce_ch6(tmp_path, **{**kw, "epochs": 2, "readout": False})
    assert s4.reused == ["ch6-data", "ch6-expert"]
    assert list(s4.closed_loop) == ["cnn-learned", "cnn-pi", "dagger1-pi", "expert"]
    assert len(s4.record["train_loss"]) == 2
    assert s4.stage_records["dagger1"]["second_output"] == "throttle"
    s5 = reproduce_ch6(tmp_path, **{**kw, "dagger_rounds": 0, "readout": False}, fresh=True)
    assert s5.reused == [] and list(s5.closed_loop) == ["cnn-learned", "cnn-pi", "expert"]
    # another recording (another steering noise) is another data set: nothing is reused but
    # the expert's closed loop
    s6 = reproduce_ch6(tmp_path, **{**kw, "dagger_rounds": 0, "readout": False}, noise_sigma=0.1)
    assert s6.reused == ["ch6-expert"]
    # a stage made by other code is refused in one line, naming it
    rec_path = again["ch6-expert"] / STAGE_FILE
    rec = json.loads(rec_path.read_text())
    rec_path.write_text(json.dumps({**rec, "fingerprint": "0" * 16}))
    with pytest.raises(StaleStageError, match=r"stage 'ch6-expert' in .* made by other code"):
        reproduce_ch6(tmp_path, **{**kw, "dagger_rounds": 0, "readout": False})


def test_closed_loop_notes_name_the_tracks_with_interventions() -> None:
    from uvnav.experiments.ch6 import _intervention_tracks

    tracks = [{"seed": 1000 + k, "interventions": n} for k, n in enumerate([0, 1, 0, 2])]
    assert _intervention_tracks(tracks) == "; interventions on tracks 1001 (1), 1003 (2)"
    assert _intervention_tracks(tracks[:1]) == ""  # none
    many = [{"seed": k, "interventions": 1} for k in range(6)]
    assert _intervention_tracks(many) == ""  # everywhere: the mean says it
