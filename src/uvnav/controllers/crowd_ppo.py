"""``crowd-ppo-v1`` and ``crowd-ppo-v2``: learned crowd laws for the holonomic robot, trained here
with PPO.

The policy (:mod:`uvnav.learning.crowd_policy`: a set encoder with attention over the humans,
then a two-layer tanh MLP) reads :func:`~uvnav.controllers.crowd_features.crowd_vector` of its
observation (the robot's goal-frame state and its ``k`` nearest seen humans, masked) and its
mean action is the command: a velocity ``V_max a`` in the goal frame, scaled onto the disc of
radius V_max.  The weights ship with uvnav (``weights/crowd-ppo-v1.safetensors``, 64 kB; their
training record is in the ``.json`` beside them) and run here in numpy (float64, no torch), so
the law is deterministic and needs only safetensors (``uvnav[learning]``) to load them.  It was
trained on CrowdNav's circle crossing (train-phase seeds, 5 humans, invisible robot); ``k`` may
be changed (the attention pools any number of humans; the weights were trained with 5).

``crowd-ppo-v2`` is the same law with other weights (``weights/crowd-ppo-v2.safetensors``): v1's
policy trained on further on a mix of the protocols the laws are judged on (CrowdNav's circle
and square crossing with 5-20 humans and the harder crowd of :mod:`uvnav.scenarios.crowd_dynamic`,
training seeds only); its record holds the ``uvnav crowd train`` command.  v2 supersedes v1 in
the campaigns (``ControllerInfo.superseded_by``); v1 stays registered for older figures.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import cache
from importlib.resources import files
from pathlib import Path
from typing import ClassVar

import numpy as np

from uvnav.controllers.base import ControllerInfo, ControllerParamsError, register
from uvnav.controllers.crowd_features import action_velocity, crowd_features
from uvnav.controllers.holonomic import HolonomicLaw
from uvnav.dynamics.omni import VelocityCommand
from uvnav.sensors.observation import Observation

#: the most human slots the law attends to
MAX_K = 64
#: the exported policy's header format
FORMAT = "uvnav-crowd-policy-v1"
#: the shipped weights, in this package
WEIGHTS = "weights/crowd-ppo-v1.safetensors"
#: the shipped policies by law name: their weights files in this package
SHIPPED: dict[str, str] = {
    "crowd-ppo-v1": WEIGHTS,
    "crowd-ppo-v2": "weights/crowd-ppo-v2.safetensors",
}
_EMBED = ("features_extractor.embed.0", "features_extractor.embed.2")
_SCORE = ("features_extractor.score.0", "features_extractor.score.2")
_PI = ("mlp_extractor.policy_net.0", "mlp_extractor.policy_net.2", "action_net")
#: the actor's tensors, as stable-baselines3's policy names them
WEIGHT_NAMES: tuple[str, ...] = tuple(
    f"{layer}.{p}" for layer in (*_EMBED, *_SCORE, *_PI) for p in ("weight", "bias")
)


@dataclass(frozen=True)
class PolicyConfig:
    """The exported policy's shape: ``k`` human slots it was trained with."""

    k: int = 5


class PolicyFileError(ValueError):
    """A policy file that cannot be read (one-line message)."""


def _relu(x: np.ndarray) -> np.ndarray:
    return np.maximum(x, 0.0)


@dataclass(frozen=True)
class CrowdPolicy:
    """The actor of an exported policy, in numpy (float64)."""

    weights: dict[str, np.ndarray]
    config: PolicyConfig

    def _linear(self, name: str, x: np.ndarray) -> np.ndarray:
        return x @ self.weights[f"{name}.weight"].T + self.weights[f"{name}.bias"]

    def mean_action(self, robot: np.ndarray, humans: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """The actor's mean action (2,) for one observation's features (``humans`` (k, 6),
        any ``k``)."""
        pair = np.hstack([np.broadcast_to(robot, (len(humans), len(robot))), humans])
        e = _relu(self._linear(_EMBED[1], _relu(self._linear(_EMBED[0], pair))))
        pooled = np.zeros(e.shape[1])
        if mask.any():
            s = self._linear(_SCORE[1], _relu(self._linear(_SCORE[0], e)))[:, 0]
            s = np.where(mask > 0.5, s, -np.inf)
            w = np.exp(s - s.max())
            pooled = (w / w.sum()) @ e
        h = np.tanh(self._linear(_PI[0], np.concatenate([robot, pooled])))
        return self._linear(_PI[2], np.tanh(self._linear(_PI[1], h)))


def read_policy(path: Path | str) -> CrowdPolicy:
    """The policy of a file written by :func:`uvnav.learning.crowd_policy.export_policy`.

    Raises:
        PolicyFileError: not such a file, or a tensor missing or not finite (one line).
    """
    try:
        from safetensors import safe_open
    except ImportError as exc:
        raise ImportError("crowd-ppo-v1 needs safetensors: pip install 'uvnav[learning]'") from exc
    path = Path(path)
    if not path.is_file():
        raise PolicyFileError(f"{path}: file not found")
    try:
        with safe_open(str(path), framework="numpy") as f:
            header = json.loads((f.metadata() or {}).get("uvnav", "{}"))
            names = set(f.keys())
            missing = [n for n in WEIGHT_NAMES if n not in names]
            if header.get("format") != FORMAT or missing:
                what = f"missing tensor {missing[0]}" if missing else f"format is not {FORMAT}"
                raise PolicyFileError(f"{path.name}: {what}")
            weights = {n: np.asarray(f.get_tensor(n), dtype=float) for n in WEIGHT_NAMES}
    except (OSError, ValueError, json.JSONDecodeError) as exc:
        if isinstance(exc, PolicyFileError):
            raise
        raise PolicyFileError(f"{path.name}: not a crowd policy file ({exc})") from None
    bad = next((n for n, w in weights.items() if not np.all(np.isfinite(w))), None)
    if bad is not None:
        raise PolicyFileError(f"{path.name}: tensor {bad} is not finite")
    return CrowdPolicy(weights, PolicyConfig(**header.get("config", {})))


def policy_file(ref: str) -> Path:
    """The policy file ``ref`` names: a shipped law's (:data:`SHIPPED`) or a path."""
    if ref in SHIPPED:
        return Path(str(files("uvnav.controllers").joinpath(SHIPPED[ref])))
    return Path(ref)


@cache
def shipped_policy(name: str = "crowd-ppo-v1") -> CrowdPolicy:
    """The shipped policy of law ``name`` (read once)."""
    return read_policy(policy_file(name))


@dataclass(frozen=True)
class CrowdPpoParams:
    """Parameters of ``crowd-ppo-v1``.

    Attributes:
        k: nearest seen humans the policy attends to (trained with 5).
        weights: a policy file to use instead of the shipped one ("": the shipped one).
    """

    k: int = 5

    weights: str = ""

    def __post_init__(self) -> None:
        if isinstance(self.k, bool) or not isinstance(self.k, int) or not 1 <= self.k <= MAX_K:
            raise ValueError(f"k must be a whole number from 1 to {MAX_K} (got {self.k!r})")


class CrowdPpo(HolonomicLaw):
    """The learned policy's mean action (module docstring)."""

    name: ClassVar[str] = "crowd-ppo-v1"

    def __init__(self, params: CrowdPpoParams | None = None) -> None:
        super().__init__()
        self.params = params or CrowdPpoParams()
        w = self.params.weights
        try:
            self.policy = read_policy(w) if w else shipped_policy(self.name)
        except PolicyFileError as exc:
            raise ControllerParamsError(f"{self.name}: weights: {exc}") from None

    def act(self, obs: Observation) -> VelocityCommand:
        self.decision_period(obs.time)
        spec = self._spec
        if not np.all(np.isfinite(np.asarray(obs.pose[:2], dtype=float))):
            return VelocityCommand(0.0, 0.0)
        robot, humans, mask = crowd_features(obs, self.params.k, spec.v_max, spec.radius)
        action = self.policy.mean_action(robot, humans, mask)
        vx, vy = action_velocity(action, obs, spec.v_max)
        self._mode = "M2" if mask.any() else "M1"
        if not (math.isfinite(vx) and math.isfinite(vy)):
            return VelocityCommand(0.0, 0.0)
        return VelocityCommand(vx, vy).clipped(spec)


register(
    ControllerInfo(
        name="crowd-ppo-v1",
        factory=CrowdPpo,
        params_type=CrowdPpoParams,
        summary="Learned crowd law: PPO with attention over the k nearest humans, trained here "
        "on CrowdNav's circle crossing (train seeds); the actor's mean, in numpy.",
        reference="Chen, Liu, Kreiss, Alahi, ICRA 2019 (SARL's attention); Schulman et al. 2017 "
        "(PPO); stable-baselines3",
        vehicle="holonomic",
        superseded_by="crowd-ppo-v2",
    )
)


class CrowdPpoV2(CrowdPpo):
    """``crowd-ppo-v2``: the law with the weights trained on the protocol mix (module docstring)."""

    name: ClassVar[str] = "crowd-ppo-v2"


register(
    ControllerInfo(
        name="crowd-ppo-v2",
        factory=CrowdPpoV2,
        params_type=CrowdPpoParams,
        summary="Learned crowd law: crowd-ppo-v1's policy trained on further on CrowdNav's circle "
        "and square crossing (5-20 humans) and the harder crowd (train seeds); numpy.",
        reference="Chen, Liu, Kreiss, Alahi, ICRA 2019 (SARL's attention); Schulman et al. 2017 "
        "(PPO); stable-baselines3",
        vehicle="holonomic",
    )
)
