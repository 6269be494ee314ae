"""The CLI refuses NaN/±inf input and prints strict JSON (issue 17, "NaN produces a score")."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from uvnav.cli.app import _dumps, app

runner = CliRunner()


def _one_error_line(output: str) -> str:
    lines = [ln for ln in output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), output
    assert "Traceback" not in output
    return lines[0]


def _strict_loads(text: str) -> Any:
    def refuse(name: str) -> None:
        raise AssertionError(f"bare {name} in the JSON output")

    return json.loads(text, parse_constant=refuse)


@pytest.mark.parametrize(
    "args",
    [
        ["drive", "evaluate", "m.safetensors", "--set-speed", "nan"],
        ["drive", "evaluate", "m.safetensors", "--set-speed", "inf"],
        ["drive", "evaluate", "m.safetensors", "--speed-factor", "nan"],
        ["drive", "evaluate", "m.safetensors", "--max-speed", "nan"],
        ["drive", "dagger", "data", "m.safetensors", "--set-speed", "nan"],
        ["drive", "train", "data", "--correction", "nan"],
        # options with a lower bound: click's check already refuses NaN, but not +inf
        ["drive", "train", "data", "--lr", "inf"],
        ["drive", "train", "data", "--target-speed-max", "inf"],
        ["drive", "speed-head", "m.safetensors", "data", "--target-speed-max", "inf"],
        ["drive", "collect", "--out", "data", "--noise", "inf"],
        ["drive", "reproduce", "--out", "data", "--noise", "inf"],
        ["sonar", "dataset", "--out", "data", "--noise", "inf"],
    ],
)
def test_non_finite_numeric_options_are_usage_errors(
    args: list[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, args)
    assert r.exit_code == 2, r.output
    option = args[-2]
    line = _one_error_line(r.output)
    assert f"'{option}': {args[-1]} is not a finite number" in line
    assert not (tmp_path / "data").exists()  # refused before anything ran


def test_drive_train_refuses_a_log_with_one_nan_steering(tmp_path: Path) -> None:
    pytest.importorskip("torch")
    from uvnav.driving.dataset import LOG_NAME, LogWriter

    data = tmp_path / "data"
    w = LogWriter(data)
    img = np.zeros((66, 200, 3), dtype=np.uint8)
    for k in range(12):
        w.write(f"k{k}", (img, img, img), steering=0.1, throttle=0.5, brake=0.0, speed=10.0)
    w.close()
    rows = (data / LOG_NAME).read_text().splitlines()
    fields = rows[4].split(",")
    fields[3] = "nan"
    rows[4] = ",".join(fields)
    (data / LOG_NAME).write_text("\n".join(rows) + "\n")
    model = tmp_path / "m.safetensors"
    r = runner.invoke(app, ["drive", "train", str(data), "--out", str(model), "--epochs", "1"])
    assert r.exit_code == 2, r.output
    line = _one_error_line(r.output)
    assert LOG_NAME in line and "row 5, column 'steering'" in line and "not a finite" in line
    assert not model.exists()


def test_drive_evaluate_refuses_a_model_with_nan_weights(tmp_path: Path) -> None:
    torch = pytest.importorskip("torch")
    from safetensors.torch import save_file

    from uvnav.learning import PilotNetConfig
    from uvnav.learning.checkpoint import FORMAT
    from uvnav.learning.pilotnet import build_pilotnet

    cfg = PilotNetConfig()
    net = build_pilotnet(cfg)
    state = {k: v.detach().clone().contiguous() for k, v in net.state_dict().items()}
    name = next(k for k in state if k.endswith("weight"))
    state[name].view(-1)[0] = torch.nan
    header = {"format": FORMAT, "kind": "pilotnet", "config": cfg.to_dict(), "record": {}}
    model = tmp_path / "m.safetensors"
    save_file(state, str(model), metadata={"uvnav": json.dumps(header)})
    r = runner.invoke(app, ["drive", "evaluate", str(model), "--seeds", "1000", "--json"])
    assert r.exit_code == 2, r.output
    line = _one_error_line(r.output)
    assert "m.safetensors" in line and name in line and "not finite" in line


def _sonar_npz(path: Path, n: int = 30) -> None:
    rng = np.random.default_rng(0)
    ranges = rng.uniform(0.5, 8.0, (n, 9))
    np.savez(
        path,
        ranges=ranges,
        inputs=ranges,
        target_distance=ranges.min(axis=1) - 0.05,
        target_index=ranges.argmin(axis=1) + 1,
        baseline_distance=ranges.min(axis=1),
        baseline_index=ranges.argmin(axis=1) + 1,
    )


def test_sonar_train_refuses_a_dataset_with_one_nan(tmp_path: Path) -> None:
    pytest.importorskip("torch")
    data = tmp_path / "d.npz"
    _sonar_npz(data)
    with np.load(data) as f:
        arrays = {k: f[k] for k in f.files}
    arrays["inputs"][4, 2] = np.nan
    np.savez(data, **arrays)
    out = tmp_path / "m"
    r = runner.invoke(app, ["sonar", "train", str(data), "--out", str(out), "--max-epochs", "3"])
    assert r.exit_code == 2, r.output
    line = _one_error_line(r.output)
    assert "d.npz" in line and "'inputs', row 4, column 2: nan is not a finite number" in line
    assert not list(tmp_path.glob("m.*"))


def test_sonar_evaluate_refuses_a_checkpoint_with_nan_scaling(tmp_path: Path) -> None:
    pytest.importorskip("torch")
    from safetensors import safe_open
    from safetensors.numpy import load_file, save_file

    data = tmp_path / "d.npz"
    _sonar_npz(data)
    r = runner.invoke(
        app, ["sonar", "train", str(data), "--out", str(tmp_path / "m"), "--max-epochs", "3"]
    )
    assert r.exit_code == 0, r.output
    with safe_open(str(tmp_path / "m.safetensors"), framework="numpy") as fh:
        meta = fh.metadata()  # the header: kept, only a scaling value is changed
    arrays = load_file(str(tmp_path / "m.safetensors"))
    arrays["y_hi"][0] = np.nan
    save_file(arrays, str(tmp_path / "m.safetensors"), metadata=meta)
    for args in (
        ["sonar", "evaluate", str(tmp_path / "m"), str(data)],
        ["simulate", "thesis-ch5-scene1", "-p", "locator=network", "-p",
         f"model={tmp_path / 'm'}"],
    ):  # fmt: skip
        r = runner.invoke(app, args)
        assert r.exit_code == 2, r.output
        assert "y_hi[0] = nan is not a finite number" in _one_error_line(r.output)


def test_cli_json_is_strict_and_writes_missing_values_as_null(
    capsys: pytest.CaptureFixture[str],
) -> None:
    data = {"a": float("nan"), "b": [np.float64("inf"), 1.5], "c": np.array([np.nan, 2.0])}
    assert _strict_loads(_dumps(data)) == {"a": None, "b": [None, 1.5], "c": [None, 2.0]}
    from uvnav.cli.drive import _print_rows

    _print_rows({"cnn-pi": {"n": 1.0, "return": float("nan"), "return_vs_expert": np.inf}}, True)
    row = _strict_loads(capsys.readouterr().out)["cnn-pi"]
    assert row == {"n": 1.0, "return": None, "return_vs_expert": None}


def test_a_steering_correction_outside_its_range_is_a_usage_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, ["drive", "train", "data", "--correction", "2"])
    assert r.exit_code == 2
    assert "'--correction': must be within [-1, 1] (got 2.0)" in _one_error_line(r.output)


def test_sonar_json_is_strict(tmp_path: Path) -> None:
    pytest.importorskip("torch")
    data = tmp_path / "d.npz"
    _sonar_npz(data)
    r = runner.invoke(
        app, ["sonar", "train", str(data), "--out", str(tmp_path / "m"), "--max-epochs", "3"]
    )
    assert r.exit_code == 0, r.output
    # a dataset of one sample: finite statistics, strict JSON
    one = tmp_path / "one.npz"
    _sonar_npz(one, n=1)
    r = runner.invoke(app, ["sonar", "evaluate", str(tmp_path / "m"), str(one), "--json"])
    assert r.exit_code == 0, r.output
    _strict_loads(r.output)
    # no sample at all: no statistic to give, refused in one line
    with np.load(one) as f:
        arrays = {k: f[k][:0] for k in f.files}
    np.savez(one, **arrays)
    r = runner.invoke(app, ["sonar", "evaluate", str(tmp_path / "m"), str(one), "--json"])
    assert r.exit_code == 2 and "has no samples (0 rows)" in _one_error_line(r.output)
