"""``uvnav drive``: collect → train → evaluate → play on a tiny configuration, and its errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

pytest.importorskip("torch")
pytest.importorskip("gymnasium")

from uvnav.cli.app import app
from uvnav.cli.drive import parse_seeds
from uvnav.driving.dataset import read_log

runner = CliRunner()


@pytest.fixture(scope="module")
def trained(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("drive")
    data = root / "data"
    r = runner.invoke(
        app,
        [
            "drive",
            "collect",
            "--out",
            str(data),
            "--episodes",
            "1",
            "--max-steps",
            "240",
            "--record-every",
            "2",
        ],
    )
    assert r.exit_code == 0, r.output
    assert len(read_log(data)) == 120
    again = runner.invoke(
        app, ["drive", "collect", "--out", str(data), "--episodes", "1", "--max-steps", "240"]
    )
    assert again.exit_code == 0 and "wrote 0 rows" in again.output  # resumed: nothing new
    other = runner.invoke(app, ["drive", "collect", "--out", str(data), "--noise", "0.1"])
    assert other.exit_code == 2 and "'noise_sigma'" in other.output  # not mixed into one folder
    meta = json.loads((data / "dataset.json").read_text())
    assert meta["fov_deg"] == 120.0 and meta["noise_sigma"] == 0.25
    model = root / "m.safetensors"
    r = runner.invoke(
        app,
        ["drive", "train", str(data), "--out", str(model), "--epochs", "1", "--batch-size", "30"],
    )
    assert r.exit_code == 0, r.output
    assert model.is_file() and model.with_suffix(".json").is_file()
    return data, model


def _short_evaluation(model: Path, *options: str) -> dict[str, dict[str, float]]:
    """``uvnav drive evaluate`` on track 1000 for 150 steps, without the expert: its JSON rows."""
    args = ["drive", "evaluate", str(model), "--seeds", "1000", "--max-steps", "150", *options]
    r = runner.invoke(app, [*args, "--no-expert", "--json"])
    assert r.exit_code == 0, r.output
    rows: dict[str, dict[str, float]] = json.loads(r.output[r.output.index("{") :])
    return rows


def test_briefly_trained_model_moves_along_the_track(trained: tuple[Path, Path]) -> None:
    _, model = trained
    row = _short_evaluation(model, "--throttle", "pi")["cnn-pi"]
    assert row["n"] == 1
    assert row["tiles_pct"] > 5.0  # it drove along the track, not in place
    assert row["mean_speed"] > 5.0
    assert row["mean_centre_distance"] < 40 / 6.0  # on average on the road


def test_camera_field_of_view_travels_from_the_data_to_the_model(
    trained: tuple[Path, Path], tmp_path: Path
) -> None:
    """The model's record keeps the field of view of its data (evaluation renders with it), and a
    dataset recorded before the field was written (then 90°) is not extended at 120°."""
    from uvnav.learning.checkpoint import read_header

    _, model = trained
    assert read_header(model)["record"]["camera_fov_deg"] == 120.0
    old = tmp_path / "old"
    old.mkdir()
    (old / "dataset.json").write_text(json.dumps({"camera": "front", "height": 66, "width": 200}))
    r = runner.invoke(app, ["drive", "collect", "--out", str(old), "--episodes", "1"])
    assert r.exit_code == 2 and "'fov_deg'" in r.output and "90.0" in r.output


def test_onnxruntime_backend_drives_the_same_episode(trained: tuple[Path, Path]) -> None:
    """The same network through onnxruntime drives track 1000 as torch does (outputs agree to
    1e-5; over 150 steps the episode's metrics agree to rounding)."""
    pytest.importorskip("onnxruntime")
    _, model = trained
    ref = _short_evaluation(model, "--throttle", "pi")["cnn-pi"]
    fast = _short_evaluation(model, "--throttle", "pi", "--backend", "onnxruntime")["cnn-pi"]
    assert fast["tiles_pct"] == pytest.approx(ref["tiles_pct"], abs=1.0)
    assert fast["return"] == pytest.approx(ref["return"], abs=5.0)
    assert fast["mean_centre_distance"] == pytest.approx(ref["mean_centre_distance"], abs=0.1)


def test_target_speed_head_trains_and_drives_with_the_learned_speed_throttle(
    trained: tuple[Path, Path], tmp_path: Path
) -> None:
    data, _ = trained
    assert read_log(data).target_speed is not None  # collect records the 8th column
    model = tmp_path / "ts.safetensors"
    r = runner.invoke(
        app,
        [
            "drive",
            "train",
            str(data),
            "--out",
            str(model),
            "--epochs",
            "2",
            "--batch-size",
            "30",
            "--head",
            "target-speed",
        ],
    )
    assert r.exit_code == 0, r.output
    rec = json.loads(model.with_suffix(".json").read_text())["record"]
    assert rec["second_output"] == "target_speed"
    assert rec["train_loss"][-1] < rec["train_loss"][0]  # the new head trains
    assert len(rec["val_target_speed_rmse"]) == 2
    rows = _short_evaluation(model)
    assert set(rows) == {"cnn-learned-speed", "cnn-pi"}  # "both" = the model's learned mode + PI
    row = rows["cnn-learned-speed"]
    assert row["tiles_pct"] > 5.0  # the network's own speed choice moves the car along
    assert row["mean_speed"] > 5.0
    bad = runner.invoke(app, ["drive", "evaluate", str(model), "--throttle", "learned"])
    assert bad.exit_code == 2 and "learned-speed" in bad.output


def test_speed_head_readout_keeps_the_steering_and_drives(
    trained: tuple[Path, Path], tmp_path: Path
) -> None:
    data, model = trained
    out = tmp_path / "ro.safetensors"
    r = runner.invoke(app, ["drive", "speed-head", str(model), str(data), "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "target speed readout" in r.output
    from uvnav.learning.checkpoint import load_checkpoint

    old, _ = load_checkpoint(model)
    new, _ = load_checkpoint(out)
    assert new.config.second_output == "target_speed"
    sd_old, sd_new = old.state_dict(), new.state_dict()
    assert all((sd_old[k] == sd_new[k]).all() for k in sd_old if not k.startswith("head.6"))
    assert (sd_old["head.6.weight"][0] == sd_new["head.6.weight"][0]).all()  # steering row kept
    row = _short_evaluation(out, "--throttle", "learned-speed")["cnn-learned-speed"]
    assert row["tiles_pct"] > 5.0 and row["mean_speed"] > 5.0


def test_play_writes_a_gif(trained: tuple[Path, Path], tmp_path: Path) -> None:
    _, model = trained
    out = tmp_path / "d.gif"
    r = runner.invoke(app, ["drive", "play", str(model), "--out", str(out), "--steps", "20"])
    assert r.exit_code == 0, r.output
    assert out.stat().st_size > 1000


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["drive", "train", "missing-folder"], "driving_log.csv"),
        (["drive", "evaluate", "missing.safetensors", "--seeds", "1"], "missing.safetensors"),
        (["drive", "evaluate", "x.safetensors", "--seeds", "5-2"], "--seeds"),
        (["drive", "collect", "--out", "x", "--camera", "side"], "--camera"),
        (["drive", "play", "x.safetensors", "--out", "x.avi"], "--out"),
        (["drive", "dagger", "d", "x.safetensors", "--throttle", "turbo"], "--throttle"),
        (["drive", "train", "d", "--head", "pedal"], "--head"),
        (["drive", "evaluate", "x.safetensors", "--throttle", "turbo"], "--throttle"),
    ],
)
def test_errors_are_one_line_exit_2(
    args: list[str], needle: str, tmp_path: Path, monkeypatch
) -> None:
    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, args)
    assert r.exit_code == 2
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and needle in lines[0]


def test_parse_seeds() -> None:
    assert parse_seeds("1000-1003,7") == [1000, 1001, 1002, 1003, 7]
    assert parse_seeds(" 4 ,, 2-2 ") == [4, 2]
    for text, why in (("a-b", "not a seed"), ("5-2", "a <= b"), ("", "no seeds")):
        with pytest.raises(ValueError, match=why):
            parse_seeds(text)
    # a range too long to run is refused before anything is built (it once ran out of memory)
    with pytest.raises(ValueError, match="more than 100000 seeds"):
        parse_seeds("0-9999999999")


def test_the_closed_loop_table_fits_80_columns(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every cell whole at 80 columns: short headers, numbers formatted to their precision."""
    from rich.console import Console

    import uvnav.cli.common as common
    from uvnav.cli.drive import _print_rows

    monkeypatch.setattr(common, "console", lambda stderr=False: Console(width=80))
    row = {
        "n": 20.0, "return": 812.345, "return_vs_expert": 0.912, "tiles_pct": 97.5, "laps": 1.0,
        "mean_centre_distance": 1.234, "off_track_events": 0.25, "autonomy": 0.9876,
        "mean_speed": 23.4,
    }  # fmt: skip
    _print_rows({"cnn-learned": row, "expert": {"n": 20.0, "return": 900.0}}, False)
    out = capsys.readouterr().out
    assert max(len(line) for line in out.splitlines()) <= 80
    assert "812.3" in out and "0.988" in out and "…" not in out
