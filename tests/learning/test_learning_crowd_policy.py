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


def test_a_mixed_env_draws_every_rule_from_training_seeds_only() -> None:
    """Each rule of the mix comes up; CrowdNav scenes are of the train phase with the drawn
    number of humans (20 on the circle included: unplaceable cases are drawn again), and the
    harder crowd's seeds lie above every seed the benchmarks judge."""
    from uvnav.envs.crowd import DYNAMIC_TRAIN_SEED, RULES

    env = CrowdNavEnv(rules=RULES, n_humans=(20, 20), cases=50)
    seen: dict[str, set[int]] = {}
    for seed in range(40):
        _, info = env.reset(seed=seed)
        seen.setdefault(info["rule"], set()).add(info["case"])
        world = env._world
        assert world is not None
        humans = sum(1 for r in world.view(0).observation.obstacles if r.is_disc)
        if info["rule"] != "crowd_dynamic":
            assert humans == 20  # CrowdNav scenes see every human (20 m)
    assert set(seen) == set(RULES)
    assert DYNAMIC_TRAIN_SEED >= 1_000_000 and all(c < 50 for c in set().union(*seen.values()))


def test_a_mixed_env_builds_crowdnav_scenes_of_the_train_phase(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import uvnav.envs.crowd as crowd_env

    calls: list[tuple[int, dict[str, object]]] = []
    real = crowd_env.crowdnav_scenario

    def spy(case: int, **kw: object) -> object:
        calls.append((case, kw))
        return real(case, **kw)  # type: ignore[arg-type]

    seeds: list[int] = []
    real_dyn = crowd_env.crowd_dynamic_scenario
    monkeypatch.setattr(crowd_env, "crowdnav_scenario", spy)

    def spy_dynamic(seed: int) -> object:
        seeds.append(seed)
        return real_dyn(seed)

    monkeypatch.setattr(crowd_env, "crowd_dynamic_scenario", spy_dynamic)
    env = CrowdNavEnv(rules=("square_crossing", "crowd_dynamic"), n_humans=(5, 8))
    for seed in range(12):
        env.reset(seed=seed)
    assert calls and all(kw["phase"] == "train" for _, kw in calls)
    assert {kw["rule"] for _, kw in calls} == {"square_crossing"}
    assert all(5 <= int(kw["n_humans"]) <= 8 for _, kw in calls)  # type: ignore[call-overload]
    assert seeds and min(seeds) >= crowd_env.DYNAMIC_TRAIN_SEED


def test_an_unknown_rule_is_refused() -> None:
    with pytest.raises(ValueError, match="rules must be some of"):
        CrowdNavEnv(rules=("corridor",))


def test_the_curriculum_rises_to_the_range_low_then_draws_the_range() -> None:
    from uvnav.learning.crowd_policy import curriculum_humans

    cfg = TrainConfig(steps=1000, humans_start=2, humans=(5, 20), curriculum=0.5)
    assert curriculum_humans(cfg, 0) == (2, 2)
    assert curriculum_humans(cfg, 125) == (3, 3)
    assert curriculum_humans(cfg, 374) == (4, 4)
    assert curriculum_humans(cfg, 375) == (5, 20) == curriculum_humans(cfg, 1000)
    assert curriculum_humans(TrainConfig(), 0) == (5, 5)  # crowd-ppo-v1's: no curriculum


def test_fine_tuning_starts_from_the_given_policys_actor() -> None:
    """A run with ``init`` (a shipped law's name) starts with that law's actor: before any update
    its mean action is the law's numpy actor's; its action noise starts at exp(log_std_init)."""
    import dataclasses

    from stable_baselines3.common.env_util import make_vec_env

    import uvnav.learning.crowd_policy as cpol
    from uvnav.controllers.crowd_ppo import shipped_policy

    cfg = dataclasses.replace(TINY, init="crowd-ppo-v1", log_std_init=-1.0)
    env = make_vec_env(CrowdNavEnv, n_envs=1, seed=5)
    model = cpol._new(cpol._sb3(), cfg, env)
    cpol.load_actor(model, cfg.init)
    policy = shipped_policy("crowd-ppo-v1")
    x = np.asarray(env.reset())
    got = np.clip(policy.mean_action(*split_vector(x[0].astype(float), 5)), -1, 1)
    np.testing.assert_allclose(model.predict(x, deterministic=True)[0][0], got, atol=1e-5)
    np.testing.assert_allclose(model.policy.log_std.detach().numpy(), [-1.0, -1.0])
    fresh = cpol._new(cpol._sb3(), TINY, env)
    assert not np.allclose(fresh.predict(x, deterministic=True)[0][0], got, atol=1e-3)


def test_the_record_holds_the_command_that_reproduces_the_weights(tmp_path: Path) -> None:
    """``command`` gives back the run's config: parsed by the CLI it trains the same config."""
    out = tmp_path / "w.safetensors"
    args = ["--steps", "64", "--n-envs", "2", "--n-steps", "32", "--humans", "5-20",
            "--humans-start", "3", "--rule", "square_crossing", "--rule", "crowd_dynamic",
            "--init", "crowd-ppo-v1", "--learning-rate", "0.0001",
            "--log-std-init", "-1"]  # fmt: skip
    r = runner.invoke(app, ["crowd", "train", "--quiet", "--json", "--out", str(out), *args])
    assert r.exit_code == 0, r.output
    record = json.loads(r.stdout)
    assert record["train"]["rules"] == ["square_crossing", "crowd_dynamic"]
    assert record["train"]["humans"] == [5, 20] and record["train"]["init"] == "crowd-ppo-v1"
    (tmp_path / "again").mkdir()
    again = tmp_path / "again" / "w.safetensors"
    words = record["command"].split()
    assert words[:3] == ["uvnav", "crowd", "train"] and "--out" in words
    words[words.index("--out") + 1] = str(again)
    r = runner.invoke(app, [*words[1:], "--quiet", "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["train"] == record["train"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--humans", "20-5"], "--humans: '20-5' is not N or LOW-HIGH"),
        (["--humans", "a"], "--humans"),
        (["--humans", "5-10", "--humans-start", "6"], "--humans-start: 6 is more than"),
        (["--rule", "corridor"], "--rule: 'corridor' is not one of"),
        (["--init", "nowhere.safetensors"], "--init: nowhere.safetensors: file not found"),
    ],
)
def test_a_bad_mix_option_is_one_line_with_status_2(args: list[str], message: str) -> None:
    r = runner.invoke(app, ["crowd", "train", "--steps", "64", *args])
    assert r.exit_code == 2, r.output
    assert message in r.output and len(r.output.strip().splitlines()) == 1
