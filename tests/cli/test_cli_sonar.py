"""``uvnav sonar``: dataset -> train -> evaluate; ``uvnav simulate`` with the trained network as
the Chapter 5 law's locator; one-line errors with status 2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("torch")

from uvnav.cli.app import app

runner = CliRunner()


def test_dataset_train_evaluate(tmp_path: Path) -> None:
    data = tmp_path / "d.npz"
    r = runner.invoke(
        app,
        ["sonar", "dataset", "-n", "30", "--seed", "1", "--subdivisions", "1", "--out", str(data)],
    )
    assert r.exit_code == 0, r.output
    assert data.is_file() and "30 samples" in r.output
    model = tmp_path / "m"
    r = runner.invoke(
        app, ["sonar", "train", str(data), "--out", str(model), "--max-epochs", "5", "--json"]
    )
    assert r.exit_code == 0, r.output
    first = json.loads(r.stdout)  # --json: stdout holds one JSON object, nothing else
    assert set(first["test"]) == {"network", "baseline"}
    assert "wrote" in r.stderr
    net, base = (first["test"][k]["distance"]["mae"] for k in ("network", "baseline"))
    worse = "is worse than the min/argmin baseline's" in r.stderr
    assert worse == (net > base)  # 5 epochs of the plain network: said when it is worse
    assert (tmp_path / "m.safetensors").is_file() and (tmp_path / "m.json").is_file()
    r = runner.invoke(
        app, ["sonar", "evaluate", str(tmp_path / "m.safetensors"), str(data), "--json"]
    )
    assert r.exit_code == 0, r.output
    table = json.loads(r.output)
    assert table["network"]["distance"]["n"] == 30


@pytest.mark.parametrize("targets", ["geometry", "readings"])
def test_every_variant_trains_to_a_loadable_checkpoint_and_evaluates(
    tmp_path: Path, targets: str
) -> None:
    from uvnav.learning.bpnn import VARIANTS, load_checkpoint
    from uvnav.sensors.sonar_dataset import SonarDataset

    data = tmp_path / "d.npz"
    r = runner.invoke(
        app,
        ["sonar", "dataset", "-n", "30", "--seed", "2", "--subdivisions", "1", "--out", str(data)],
    )
    assert r.exit_code == 0, r.output
    with np.load(data) as z:
        ds = SonarDataset.from_arrays({k: z[k] for k in z.files})
    for variant in VARIANTS:
        out = tmp_path / f"m_{variant}"
        args = ["sonar", "train", str(data), "--out", str(out), "--max-epochs", "3", "--json"]
        r = runner.invoke(app, [*args, "--variant", variant, "--targets", targets])
        assert r.exit_code == 0, r.output
        assert (json.loads(r.stdout)["variant"], json.loads(r.stdout)["targets"]) == (
            variant,
            targets,
        )
        model = load_checkpoint(out)  # the one checkpoint format, either kind of network
        assert (model.variant, model.target_kind) == (variant, targets)
        assert model.config.residual == (variant != "plain")
        r = runner.invoke(
            app, ["sonar", "evaluate", str(out) + ".safetensors", str(data), "--json"]
        )
        assert r.exit_code == 0, r.output
        table = json.loads(r.stdout)
        assert (table["variant"], table["targets"]) == (variant, targets)
        # errors against the targets the network learnt, not the other kind
        expect = ds.targets(targets)[:, 0] - model.predict(ds.inputs, ds.baseline())[:, 0]
        assert table["network"]["distance"]["lo"] == pytest.approx(expect.min())
        assert table["network"]["distance"]["hi"] == pytest.approx(expect.max())


def test_bad_inputs_are_one_line_errors(tmp_path: Path) -> None:
    junk = tmp_path / "junk.npz"
    junk.write_text("not a zip")
    for args in (
        ["sonar", "train", str(tmp_path / "missing.npz")],
        ["sonar", "train", str(junk)],
        ["sonar", "evaluate", str(tmp_path / "nomodel"), str(junk)],
        ["simulate", "random-ch5:x"],
        ["simulate", "thesis-ch5-scene1", "-p", "locator=network"],
        ["simulate", "thesis-ch5-scene1", "-p", "locator=network", "-p", "model=nothing"],
        ["sonar", "train", str(junk), "--variant", "deep"],
        ["sonar", "train", str(junk), "--targets", "truth"],
    ):
        r = runner.invoke(app, args)
        assert r.exit_code == 2, (args, r.output)
        lines = [ln for ln in r.output.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: "), r.output
        assert "Traceback" not in r.output


@pytest.mark.slow
@pytest.mark.parametrize("locator", ["network", "oracle"])
def test_simulate_runs_the_law_with_the_locator_its_parameters_name(
    tmp_path: Path, locator: str
) -> None:
    from uvnav.controllers.zhang_uuv3d import ZhangUUV3D, make_locator
    from uvnav.scenarios.catalog import resolve
    from uvnav.scenarios.ch5 import build_uuv3d
    from uvnav.sim.run import run_episode

    model = str(tmp_path / "m") if locator == "network" else ""
    if model:
        data = str(tmp_path / "d.npz")
        for args in (
            ["sonar", "dataset", "-n", "30", "--seed", "3", "--subdivisions", "1", "--out", data],
            ["sonar", "train", data, "--out", model, "--max-epochs", "3"],
        ):
            assert runner.invoke(app, args).exit_code == 0
    given = ["-p", f"locator={locator}", *(["-p", f"model={model}"] if model else [])]
    r = runner.invoke(app, ["simulate", "thesis-ch5-scene1", *given, "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    scene = resolve("thesis-ch5-scene1")
    law = ZhangUUV3D(None, make_locator(locator, model))
    direct = run_episode(build_uuv3d(scene.scenario), law, scene.kind.episode_rng(0), record=False)
    assert out["locator"] == locator and law.oracle == (locator == "oracle")
    assert (out["status"], out["path_length"], out["min_clearance"]) == (
        direct.status,
        direct.metrics.path_length,
        direct.metrics.min_clearance,
    )
