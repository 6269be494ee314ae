"""Training the learned crowd laws ``crowd-ppo-v*``: PPO (stable-baselines3) with a set encoder.

The policy reads :func:`uvnav.controllers.crowd_features.crowd_vector` (the robot's goal-frame
state and its ``k`` nearest seen humans, masked) through :class:`SetAttentionExtractor`: each
human, concatenated with the robot's state, goes through a two-layer ReLU MLP (an embedding); a
small MLP scores each embedding; a softmax over the seen humans' scores (empty slots weigh 0)
pools the embeddings; the features are the robot's state and the pooled embedding (the
attention-over-humans of SARL, Chen et al., ICRA 2019, as PPO's shared features).  PPO's actor
and critic are two-layer tanh MLPs on them; the law acts with the actor's mean
(:mod:`uvnav.controllers.crowd_ppo` runs it in numpy from the exported weights).

:func:`train_crowd_policy` trains on :class:`uvnav.envs.crowd.CrowdNavEnv` (training cases of
the config's scenes: CrowdNav's circle and square crossing, the harder crowd) and
:func:`export_policy` writes the actor's weights as safetensors with a JSON header (config +
training record: seed, steps, CPU time, reward, curriculum).  A run may start from an exported
policy (``init``: fine-tuning): its actor's weights are loaded into the new model, whose critic
starts fresh and whose action noise starts at ``exp(log_std_init)``.

A long run loses nothing when interrupted: with a ``checkpoint`` path, PPO's whole state (the
policy, the optimiser, the step count) is saved there every ``every`` steps and when the run is
interrupted (Ctrl-C), with the run's config and CPU time beside it (``<checkpoint>.json``); a run
given the same path and config continues from it (:class:`CheckpointMismatchError` for another
config).  The resumed run's environments restart from fresh cases, so its weights are not bit for
bit an uninterrupted run's.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.controllers.crowd_features import HUMAN_DIM, ROBOT_DIM
from uvnav.controllers.crowd_ppo import FORMAT, WEIGHT_NAMES, PolicyConfig
from uvnav.stages import write_atomic


def _torch() -> Any:
    import torch

    return torch


def _sb3() -> Any:
    try:
        import stable_baselines3
    except ImportError as exc:
        raise ImportError(
            "training the crowd policy needs stable-baselines3: pip install 'uvnav[learning]'"
        ) from exc
    return stable_baselines3


def make_extractor_class() -> type:
    """:class:`SetAttentionExtractor`, defined once torch and stable-baselines3 are imported."""
    torch = _torch()
    nn = torch.nn
    from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

    class SetAttentionExtractor(BaseFeaturesExtractor):
        """Per-human MLP + masked attention pooling (module docstring)."""

        def __init__(self, observation_space: Any, k: int = 5, embed: int = 64, score: int = 32):
            super().__init__(observation_space, features_dim=ROBOT_DIM + embed)
            self.k = k
            self.embed = nn.Sequential(
                nn.Linear(ROBOT_DIM + HUMAN_DIM, embed), nn.ReLU(),
                nn.Linear(embed, embed), nn.ReLU(),
            )  # fmt: skip
            self.score = nn.Sequential(nn.Linear(embed, score), nn.ReLU(), nn.Linear(score, 1))

        def forward(self, x: Any) -> Any:
            robot = x[:, :ROBOT_DIM]
            slots = x[:, ROBOT_DIM:].reshape(x.shape[0], self.k, HUMAN_DIM + 1)
            humans, mask = slots[..., :HUMAN_DIM], slots[..., HUMAN_DIM]
            pair = torch.cat([robot.unsqueeze(1).expand(-1, self.k, -1), humans], dim=-1)
            e = self.embed(pair)
            s = self.score(e).squeeze(-1).masked_fill(mask < 0.5, -1e9)
            w = torch.softmax(s, dim=-1) * mask
            return torch.cat([robot, (w.unsqueeze(-1) * e).sum(dim=1)], dim=-1)

    return SetAttentionExtractor


@dataclass(frozen=True)
class TrainConfig:
    """What a training run is given (all of it is kept in the training record).

    Attributes:
        steps: PPO's environment steps in all.
        seed: seed of PPO, its envs and the drawn cases.
        n_envs: envs stepped together.
        k: human slots of the observation.
        humans_start: humans per scene at the start of a linear curriculum to ``humans[0]``
            over the first ``curriculum`` share of the steps (``humans[0]``: no curriculum).
        curriculum: share of the steps the curriculum lasts.
        humans: humans per CrowdNav scene after the curriculum, ``(low, high)`` drawn per
            episode.
        rules: the scenes drawn from (:data:`uvnav.envs.crowd.RULES`).
        init: an exported policy file the actor starts from ("": a new policy).
        log_std_init: the log standard deviation the action noise starts at.
        n_steps, batch_size, epochs, learning_rate, gamma, gae_lambda, ent_coef: PPO's
            (the learning rate falls linearly to 0 over the run).
    """

    steps: int = 1_000_000
    seed: int = 0
    n_envs: int = 8
    k: int = 5
    humans_start: int = 5
    curriculum: float = 0.3
    n_steps: int = 256
    batch_size: int = 256
    epochs: int = 10
    learning_rate: float = 3e-4
    gamma: float = 0.99
    gae_lambda: float = 0.95
    ent_coef: float = 0.0
    humans: tuple[int, int] = (5, 5)
    rules: tuple[str, ...] = ("circle_crossing",)
    init: str = ""
    log_std_init: float = 0.0


def curriculum_humans(cfg: TrainConfig, steps: int) -> tuple[int, int]:
    """The envs' ``(low, high)`` humans after ``steps`` steps: one count rising linearly from
    ``humans_start`` to ``humans[0]`` over the curriculum, then ``humans``."""
    low, high = cfg.humans
    share = steps / max(cfg.steps * cfg.curriculum, 1.0)
    n = cfg.humans_start + int(share * (low + 1 - cfg.humans_start))
    return (n, n) if n < low else (low, high)


def _curriculum_callback(cfg: TrainConfig) -> Any:
    from stable_baselines3.common.callbacks import BaseCallback

    class Curriculum(BaseCallback):
        """Raises the envs' human count over the curriculum (:func:`curriculum_humans`)."""

        n = (-1, -1)

        def _on_step(self) -> bool:
            n = curriculum_humans(cfg, self.num_timesteps)
            if n != self.n:
                self.training_env.set_attr("humans", n)
                self.n = n
            return True

    return Curriculum()


#: steps between two checkpoints of a training run
CHECKPOINT_EVERY = 100_000


class CheckpointMismatchError(ValueError):
    """A checkpoint made by a run of another config (one line)."""


def train_crowd_policy(
    cfg: TrainConfig,
    *,
    log: Any = None,
    checkpoint: Path | None = None,
    every: int = CHECKPOINT_EVERY,
) -> tuple[Any, dict[str, Any]]:
    """Train PPO on :class:`~uvnav.envs.crowd.CrowdNavEnv`; returns ``(model, record)``.

    ``log``: a callable given one line per PPO update (steps, mean return, success share) or
    ``None``.  ``checkpoint``: a ``.zip`` path; an existing checkpoint there is continued (module
    docstring), and the run saves its state there every ``every`` steps and on Ctrl-C (then
    re-raises the interrupt).

    Raises:
        CheckpointMismatchError: the checkpoint was made with another config.
    """
    torch = _torch()
    sb3 = _sb3()
    from stable_baselines3.common.env_util import make_vec_env

    from uvnav.envs.crowd import CROWD_REWARD, CrowdNavEnv

    meta = _checkpoint_meta(cfg, checkpoint)
    spent = float(meta["cpu_seconds"]) if meta else 0.0
    torch.set_num_threads(1)
    cpu0, wall0 = time.process_time(), time.perf_counter()
    env = make_vec_env(CrowdNavEnv, n_envs=cfg.n_envs, seed=cfg.seed,
                       env_kwargs={"k": cfg.k, "n_humans": curriculum_humans(cfg, 0),
                                   "rules": tuple(cfg.rules)})  # fmt: skip
    if meta and checkpoint:
        model = _load(sb3, cfg, env, checkpoint)
    else:
        model = _new(sb3, cfg, env)
        if cfg.init:
            load_actor(model, cfg.init)
    callbacks = [_curriculum_callback(cfg), _progress_callback(log)]
    done = int(model.num_timesteps)

    def save() -> None:
        if checkpoint is not None:
            _save(model, cfg, checkpoint, spent + time.process_time() - cpu0)

    if checkpoint is not None:
        callbacks.append(_checkpoint_callback(save, every))
    try:
        model.learn(
            total_timesteps=max(cfg.steps - done, 0), callback=callbacks,
            reset_num_timesteps=done == 0,
        )  # fmt: skip
    except KeyboardInterrupt:
        save()
        raise
    finally:
        env.close()
    record = {
        "algorithm": "PPO (stable-baselines3 " + sb3.__version__ + ")",
        "env": env_text(cfg),
        "train": asdict(cfg),
        "reward": asdict(CROWD_REWARD),
        "timesteps": int(model.num_timesteps),
        "cpu_seconds": round(spent + time.process_time() - cpu0, 1),
        "wall_seconds": round(time.perf_counter() - wall0, 1),
        "torch": torch.__version__,
    }
    return model, record


def env_text(cfg: TrainConfig) -> str:
    """The training scenes of ``cfg``, in words (the record's ``env``)."""
    from uvnav.envs.crowd import DYNAMIC_TRAIN_SEED

    names = {
        "circle_crossing": "crowdnav-circle",
        "square_crossing": "crowdnav-square",
        "crowd_dynamic": f"crowd-dynamic (seeds {DYNAMIC_TRAIN_SEED} + case, 20 humans, 5 m "
        "sensing)",
    }
    scenes = ", ".join(names[r] for r in cfg.rules)
    low, high = cfg.humans
    crowd = f"{low}" if low == high else f"{low}-{high}"
    return (
        f"CrowdNavEnv: {scenes} drawn uniformly; CrowdNav scenes of the train phase (seeds "
        f"2000 + case) with {crowd} humans; holonomic robot, invisible to ORCA humans"
    )


def load_actor(model: Any, path: Path | str) -> None:
    """Set ``model``'s actor (:data:`~uvnav.controllers.crowd_ppo.WEIGHT_NAMES`) to the exported
    policy's at ``path`` (or a shipped law's, by name: :func:`~uvnav.controllers.crowd_ppo.
    policy_file`).

    Raises:
        PolicyFileError: not a policy file (one line).
    """
    from uvnav.controllers.crowd_ppo import policy_file, read_policy

    torch = _torch()
    weights = read_policy(policy_file(str(path))).weights
    state = {n: torch.as_tensor(weights[n], dtype=torch.float32) for n in WEIGHT_NAMES}
    model.policy.load_state_dict(state, strict=False)


def _new(sb3: Any, cfg: TrainConfig, env: Any) -> Any:
    """A new PPO model of ``cfg`` (module docstring) stepping ``env``."""
    return sb3.PPO(
        "MlpPolicy", env, n_steps=cfg.n_steps, batch_size=cfg.batch_size, n_epochs=cfg.epochs,
        learning_rate=lambda left: cfg.learning_rate * left, gamma=cfg.gamma,
        gae_lambda=cfg.gae_lambda, ent_coef=cfg.ent_coef, seed=cfg.seed, device="cpu", verbose=0,
        policy_kwargs={
            "features_extractor_class": make_extractor_class(),
            "features_extractor_kwargs": {"k": cfg.k},
            "net_arch": {"pi": [64, 64], "vf": [64, 64]},
            "log_std_init": cfg.log_std_init,
        },
    )  # fmt: skip


def _checkpoint_meta(cfg: TrainConfig, path: Path | None) -> dict[str, Any] | None:
    """What a run of ``cfg`` saved beside its checkpoint at ``path`` (steps, CPU seconds), or
    ``None`` when there is none.

    Raises:
        CheckpointMismatchError: the checkpoint was made with another config.
    """
    if path is None or not Path(path).is_file():
        return None
    meta: dict[str, Any] = json.loads(Path(path).with_suffix(".json").read_text())
    if meta.get("train") != json.loads(json.dumps(asdict(cfg))):
        raise CheckpointMismatchError(
            f"{path}: a checkpoint of a run with other options ({meta.get('train')}); delete it "
            "or give the same options"
        )
    return meta


def _load(sb3: Any, cfg: TrainConfig, env: Any, path: Path) -> Any:
    """The PPO model saved at ``path``, stepping ``env``, with ``cfg``'s learning-rate schedule."""
    schedule = {"learning_rate": lambda left: cfg.learning_rate * left}
    schedule["lr_schedule"] = schedule["learning_rate"]
    return sb3.PPO.load(str(path), env=env, device="cpu", custom_objects=schedule)


def _save(model: Any, cfg: TrainConfig, path: Path, cpu_seconds: float) -> None:
    """PPO's state at ``path`` (written whole or not at all) and its config and CPU time beside
    it."""
    path = Path(path)
    tmp = path.with_name(path.stem + ".tmp.zip")
    model.save(str(tmp))
    meta = {"train": asdict(cfg), "timesteps": int(model.num_timesteps), "cpu_seconds": cpu_seconds}
    write_atomic(path.with_suffix(".json"), (json.dumps(meta, indent=1) + "\n").encode())
    tmp.replace(path)


def _checkpoint_callback(save: Any, every: int) -> Any:
    from stable_baselines3.common.callbacks import BaseCallback

    class Checkpoint(BaseCallback):
        """Saves the run's state after the first rollout past each ``every`` steps."""

        last = 0

        def _on_step(self) -> bool:
            return True

        def _on_rollout_end(self) -> None:
            if self.num_timesteps - self.last >= every:
                self.last = self.num_timesteps
                save()

    return Checkpoint()


def _progress_callback(log: Any) -> Any:
    from stable_baselines3.common.callbacks import BaseCallback

    class Progress(BaseCallback):
        """One line per rollout: steps, episodes, success / collision / timeout shares."""

        def __init__(self) -> None:
            super().__init__()
            self.counts: dict[str, int] = {}

        def _on_step(self) -> bool:
            for info, done in zip(self.locals["infos"], self.locals["dones"], strict=True):
                if done:
                    s = str(info.get("status"))
                    self.counts[s] = self.counts.get(s, 0) + 1
            return True

        def _on_rollout_end(self) -> None:
            n = sum(self.counts.values())
            if log is not None and n:
                shares = " ".join(f"{k} {v / n:.2f}" for k, v in sorted(self.counts.items()))
                log(f"steps {self.num_timesteps} episodes {n} {shares}")
            self.counts = {}

    return Progress()


def actor_weights(model: Any) -> dict[str, np.ndarray]:
    """The actor's weights (features extractor, policy MLP, action mean) as float32 numpy
    arrays named by :data:`uvnav.controllers.crowd_ppo.WEIGHT_NAMES`."""
    state = model.policy.state_dict()
    return {
        name: state[name].detach().cpu().numpy().astype(np.float32).copy() for name in WEIGHT_NAMES
    }


def export_policy(model: Any, record: dict[str, Any], path: Path | str, k: int) -> Path:
    """Write the actor's weights (safetensors; header under metadata key ``uvnav``) and the
    header's JSON copy beside them; returns ``path``."""
    from safetensors.numpy import save

    path = Path(path)
    header = {"format": FORMAT, "config": asdict(PolicyConfig(k=k)), "record": record}
    text = json.dumps(header, sort_keys=True)
    write_atomic(path, save(actor_weights(model), metadata={"uvnav": text}))
    write_atomic(path.with_suffix(".json"), (json.dumps(header, indent=2) + "\n").encode())
    return path
