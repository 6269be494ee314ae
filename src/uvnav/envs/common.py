"""Pieces shared by the Chapter 3 and Chapter 4 environments (``uvnav/Nav3D-v0``,
``uvnav/UUV2D-v0``): their decision loop (:class:`VehicleWorldEnv`), comparing observations by
content, the generic :class:`SimView` of ``info["uvnav"]``, loading a scene or a per-episode
random scene, and painting polygons into an RGB frame.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from uvnav.envs.core import RewardConfig, checked_actions
from uvnav.envs.nav2d import reward_config

try:
    import gymnasium as gym
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("uvnav.envs needs gymnasium: pip install 'uvnav[envs]'") from exc


def content_equal(a: Any, b: Any) -> bool:
    """Equality by content: dataclasses field by field, numpy arrays element-wise (NaN equal to
    NaN), sequences and dicts item by item, anything else with ``==``.

    Gymnasium's determinism checks compare ``info`` dicts; the uvnav observations hold arrays,
    whose ``==`` is element-wise, hence this."""
    if a is b:
        return True
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        x, y = np.asarray(a), np.asarray(b)
        if x.shape != y.shape:
            return False
        if x.dtype.kind in "fc" and y.dtype.kind in "fc":
            return bool(np.array_equal(x, y, equal_nan=True))
        return bool(np.array_equal(x, y))
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        if type(a) is not type(b):
            return False
        return all(
            content_equal(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a)
        )
    if isinstance(a, list | tuple):
        if not isinstance(b, list | tuple) or len(a) != len(b):
            return False
        return all(content_equal(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        if not isinstance(b, dict) or a.keys() != b.keys():
            return False
        return all(content_equal(a[k], b[k]) for k in a)
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True
    return bool(a == b)


@dataclass(frozen=True, eq=False)
class SimView:
    """What a uvnav law is given at this decision (``info["uvnav"]`` of the Chapter 3 / 4 envs):
    its observation (:class:`~uvnav.sensors.sensing3d.Observation3D` or
    :class:`~uvnav.sensors.sonar2d.SonarObservation`) and its vehicle limits, plus the env's
    inverse action map ``to_action(command) -> action`` (what :func:`uvnav.envs.as_policy` uses).

    Equality compares the observation and the limits by content (:func:`content_equal`).
    """

    observation: Any
    spec: Any
    to_action: Callable[[Any], np.ndarray]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, SimView):
            return NotImplemented
        return content_equal(self.spec, other.spec) and content_equal(
            self.observation, other.observation
        )

    __hash__ = None  # type: ignore[assignment]


def scene_for_episode(
    scenario: Any, generators: Mapping[str, Callable[..., Any]], episode_seed: int
) -> Any:
    """The scene of an episode: ``scenario`` itself, or — when it names a generator without a
    seed (``"random-ch3"``) — that generator's scene number ``episode_seed`` (a fresh random
    scene every episode)."""
    if isinstance(scenario, str):
        return generators[scenario](episode_seed)
    return scenario


class VehicleWorldEnv(gym.Env[np.ndarray, np.ndarray]):
    """The decision loop of ``uvnav/Nav3D-v0`` and ``uvnav/UUV2D-v0`` over the simulator's own
    vehicle world: one env step applies the action's command and advances the world
    ``ratio`` integration steps (or until the episode ends), keeping the smallest clearance
    over them for the reward (:class:`~uvnav.envs.core.RewardConfig`)."""

    scenario: Any

    def _configure(
        self,
        scenario: Any,
        generators: Mapping[str, Callable[[int], Any]],
        load: Callable[[Any], Any],
        render_mode: str | None,
        reward: RewardConfig | dict[str, float] | None,
    ) -> Any:
        """Set the scene (a generator's name, or anything ``load`` turns into a scene), the
        render mode and the reward; the scene of the first episode is returned (the generator's
        scene 0 for a generator)."""
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array' (got {render_mode!r})")
        self._generators = dict(generators)
        if isinstance(scenario, str) and scenario in self._generators:
            self.scenario = scenario
            first = self._generators[scenario](0)
        else:
            self.scenario = first = load(scenario)
        self.render_mode = render_mode
        self.reward_config = reward_config(reward)
        self._world: Any = None
        self._obs: Any = None
        self._clearance = math.inf
        return first

    # the subclass's: the started world of one episode of ``scene``, the vehicle command of an
    # action, the distance [m] to the goal now, the observation vector and the info
    def _new_world(self, scene: Any, episode_seed: int) -> Any:
        raise NotImplementedError

    def _command(self, action: np.ndarray) -> Any:
        raise NotImplementedError

    def _distance(self) -> float:
        raise NotImplementedError

    def _vector(self) -> np.ndarray:
        raise NotImplementedError

    def _info(self) -> dict[str, Any]:
        raise NotImplementedError

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        episode_seed = int(self.np_random.integers(2**31 - 1))
        sc = scene_for_episode(self.scenario, self._generators, episode_seed)
        self._world = world = self._new_world(sc, episode_seed)
        self._clearance = world.clearance
        self._obs = world.observe()
        return self._vector(), self._info()

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        world = self._world
        if world is None:
            raise RuntimeError("call reset() before step()")
        if world.done:
            raise RuntimeError("the episode is over: call reset()")
        action = checked_actions("action", action, self.action_space.shape or ())
        rw = self.reward_config
        before = self._distance()
        world.apply(self._command(action))
        low = math.inf
        for _ in range(world.ratio):
            world.advance()
            low = min(low, world.clearance)
            if world.done:
                break
        self._clearance = low
        after = self._distance()
        terminated = world.done and world.status in ("success", "collision")
        truncated = world.done and not terminated
        reward = rw.reward(before - after, low, world.status if terminated else "running")
        self._obs = world.observe()
        return self._vector(), float(reward), terminated, truncated, self._info()

    def close(self) -> None:
        self._world = None
        self._obs = None


def fill_polygon(
    img: np.ndarray,
    polygon: np.ndarray,
    colour: tuple[int, int, int],
    gx: np.ndarray,
    gy: np.ndarray,
) -> None:
    """Paint the pixels of ``img`` whose centres (``gx``, ``gy``) [m] lie inside ``polygon``
    ((n, 2) [m]; even-odd rule via shapely) with ``colour`` (in place)."""
    import shapely

    if len(polygon) < 3:
        return
    poly = shapely.Polygon(np.asarray(polygon, dtype=float))
    if not poly.is_valid:
        poly = shapely.make_valid(poly)
    xmin, ymin, xmax, ymax = poly.bounds
    box = (gx >= xmin) & (gx <= xmax) & (gy >= ymin) & (gy <= ymax)
    if not box.any():
        return
    inside = np.zeros(gx.shape, dtype=bool)
    inside[box] = shapely.contains_xy(poly, gx[box], gy[box])
    img[inside] = colour
