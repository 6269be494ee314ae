"""``uvnav crowd train`` on a tiny budget, its weights file, and the law's numpy actor against
stable-baselines3's own prediction."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("stable_baselines3")
pytest.importorskip("gymnasium")

from uvnav.cli.app import app
from uvnav.controllers.base import make_law
from uvnav.controllers.crowd_features import split_vector
from uvnav.controllers.crowd_ppo import read_policy
from uvnav.envs.crowd import CrowdNavEnv
from uvnav.learning.crowd_policy import TrainConfig, export_policy, train_crowd_policy

runner = CliRunner()
TINY = TrainConfig(steps=128, n_envs=2, n_steps=64, batch_size=64, epochs=1)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, dict[str, object], Path]:
    model, record = train_crowd_policy(TINY)
    path = export_policy(model, record, tmp_path_factory.mktemp("w") / "p.safetensors", TINY.k)
    return model, record, path


def test_the_numpy_actor_is_the_trained_policys_mean_action(tiny: tuple) -> None:
    """The law's actor (numpy, float64) gives stable-baselines3's deterministic action, also with
    empty slots (fewer humans than k) and none at all."""
    model, _, path = tiny
    policy = read_policy(path)
    env = CrowdNavEnv(n_humans=(0, 5))
    rows = []
    for seed in range(6):
        x, _ = env.reset(seed=seed)
        for _ in range(3):
            rows.append(x)
            x = env.step(np.array([0.5, 0.2], dtype=np.float32))[0]
    batch = np.stack(rows)
    assert (split_vector(batch, 5)[2].sum(axis=1) < 5).any()  # some slots were empty
    expected, _ = model.predict(batch, deterministic=True)
    got = [np.clip(policy.mean_action(*split_vector(r.astype(float), 5)), -1, 1) for r in batch]
    np.testing.assert_allclose(np.array(got), expected, atol=1e-5)


def test_the_record_says_how_the_weights_were_trained(tiny: tuple) -> None:
    _, record, path = tiny
    header = json.loads(path.with_suffix(".json").read_text())
    assert header["record"] == json.loads(json.dumps(record))
    assert header["record"]["train"]["seed"] == 0 and header["record"]["timesteps"] >= 128
    assert header["record"]["cpu_seconds"] > 0 and header["config"] == {"k": 5}
    assert "train phase" in header["record"]["env"]


def test_crowd_train_writes_weights_the_law_drives_with(tmp_path: Path) -> None:
    out = tmp_path / "w.safetensors"
    r = runner.invoke(
        app, ["crowd", "train", "--steps", "128", "--n-envs", "2", "--n-steps", "64",
              "--seed", "3", "--quiet", "--json", "--out", str(out)],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["train"]["seed"] == 3
    assert out.is_file() and out.with_suffix(".json").is_file()
    assert list(tmp_path.glob("*.ckpt.*")) == []  # no checkpoint left once the weights are out
    r = runner.invoke(
        app, ["simulate", "crowdnav-circle:0", "--controller", "crowd-ppo-v1",
              "--param", f"weights={out}", "--json"],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["status"] in ("success", "collision", "timeout")
    assert make_law("crowd-ppo-v1", weights=str(out)).policy.config.k == 5


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--out", "w.pt"], "must end in .safetensors"),
        (["--steps", "0"], "--steps"),
        (["--steps", "1000000000"], "is more than 100000000"),
        (["--seed", "-1"], "--seed"),
    ],
)
def test_a_bad_option_is_one_line_with_status_2(args: list[str], message: str) -> None:
    r = runner.invoke(app, ["crowd", "train", *args])
    assert r.exit_code == 2, r.output
    assert message in r.output


def test_an_interrupted_run_continues_from_its_checkpoint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C after the first checkpoint leaves the run's state on disk; the same config
    continues it to its step count (CPU time added up); another config is refused in one
    line."""
    import dataclasses

    import uvnav.learning.crowd_policy as cpol

    cfg = TrainConfig(steps=256, n_envs=2, n_steps=32, batch_size=64, epochs=1)
    ckpt = tmp_path / "p.ckpt.zip"
    real, calls = cpol._save, []

    def save_then_interrupt(*args: object, **kwargs: object) -> None:
        real(*args, **kwargs)  # type: ignore[arg-type]
        calls.append(1)
        if len(calls) == 1:
            raise KeyboardInterrupt

    monkeypatch.setattr(cpol, "_save", save_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        train_crowd_policy(cfg, checkpoint=ckpt, every=64)
    saved = json.loads(ckpt.with_suffix(".json").read_text())
    assert ckpt.is_file() and 64 <= saved["timesteps"] < cfg.steps
    monkeypatch.setattr(cpol, "_save", real)
    model, record = train_crowd_policy(cfg, checkpoint=ckpt, every=64)
    assert record["timesteps"] == model.num_timesteps == cfg.steps
    assert record["cpu_seconds"] >= saved["cpu_seconds"] > 0
    with pytest.raises(cpol.CheckpointMismatchError, match="other options"):
        train_crowd_policy(dataclasses.replace(cfg, seed=1), checkpoint=ckpt)


def test_the_cli_refuses_to_overwrite_an_interrupted_run(tmp_path: Path) -> None:
    """A checkpoint beside --out is continued with --resume only, never silently restarted."""
    out = tmp_path / "w.safetensors"
    (tmp_path / "w.ckpt.zip").write_bytes(b"")
    result = runner.invoke(app, ["crowd", "train", "--out", str(out), "--steps", "64"])
    assert result.exit_code == 2
    assert "--resume continues it" in result.output and len(result.output.strip().splitlines()) == 1
