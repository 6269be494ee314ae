"""Plug-in motion models and sensors (entry-point groups ``uvnav.motions``, ``uvnav.sensors``):
a scene uses them from YAML, the world steps and reads them, bad names and parameters are one
line when the scene is loaded, taken names are refused."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import uvnav.core as core
import uvnav.obstacles.motion as motion
import uvnav.sensors.plugins as sensors
from uvnav.obstacles.motion import ObstacleState
from uvnav.scenarios import ScenarioError, build_episode, scenario_from_dict
from uvnav.sim import run_rng
from uvnav.sim.run import run_episode


class FakeEntryPoint:
    def __init__(self, name: str, obj: Any) -> None:
        self.name, self.value, self._obj = name, f"plugin:{name}", obj

    def load(self) -> Any:
        return self._obj


class Circling:
    """A body on a circle of ``radius`` [m] at ``speed`` [m/s] (a test plug-in)."""

    def __init__(self, rng: np.random.Generator, *, speed: float, radius: float) -> None:
        if speed <= 0 or radius <= 0:
            raise ValueError(f"speed and radius must be > 0 (got {speed}, {radius})")
        self.speed, self.omega = speed, speed / radius

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState:
        course = self.omega * (t + dt)
        vel = self.speed * np.array([np.cos(course), np.sin(course)])
        return ObstacleState(state.position + vel * dt, state.heading, vel, 0.0)

    def speed_bound(self) -> float:
        return self.speed

    def turn_bound(self) -> float:
        return 0.0


def nearest_gap(pose: Any, field: Any, rng: np.random.Generator, *, noise: float = 0.0) -> float:
    """A test sensor: the distance [m] to the nearest body centre, with noise."""
    d = np.hypot(*(field.centres - pose[:2]).T)
    return float(d.min() + rng.normal(0.0, noise)) if len(d) else float("inf")


@pytest.fixture(autouse=True)
def plugins(monkeypatch: pytest.MonkeyPatch) -> Any:
    groups = {
        motion.MOTION_GROUP: [FakeEntryPoint("circling", Circling)],
        sensors.SENSOR_GROUP: [FakeEntryPoint("gap", nearest_gap)],
    }
    monkeypatch.setattr(core, "entry_points", lambda group: groups.get(group, []))
    core.load_plugins.cache_clear()  # load these fakes, and forget them afterwards
    yield groups
    core.load_plugins.cache_clear()


def scene(motion_params: dict[str, Any], sensor: str = "gap") -> dict[str, Any]:
    return {
        "name": "plug",
        "robot": {"start": [0, 0], "goal": [8, 0], "v_max": 1.0, "u_max": 1.0},
        "t_max": 3,
        "sensing": {"plugins": [{"name": sensor, "params": {"noise": 0.01}}]},
        "obstacles": [
            {
                "body": {"disc": 0.3},
                "start": {"position": [4.0, 3.0]},
                "motion": {"type": "plugin", "name": "circling", "params": motion_params},
            }
        ],
        "controller": {"name": "straight-v1"},
    }


class Recorder:
    name = "recorder"
    oracle = False
    mode = "M1"

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        self.extras: list[Any] = []

    def act(self, obs: Any) -> Any:
        from uvnav.dynamics.unicycle import UnicycleCommand

        self.extras.append(obs.extras)
        return UnicycleCommand(0.5, 0.0)


def test_a_scene_moves_a_plugin_body_and_reads_a_plugin_sensor() -> None:
    sc = scenario_from_dict(scene({"speed": 0.5, "radius": 2.0}))
    law = Recorder()
    a = run_episode(build_episode(sc, 0), law, run_rng(0))
    assert a.trajectory is not None
    centres = a.trajectory.obstacle_centres[:, 0]
    assert np.ptp(centres[:, 0]) > 0.1 and np.ptp(centres[:, 1]) > 0.1  # it moved, on a curve
    gaps = [e["gap"] for e in law.extras]
    assert len(gaps) == len(a.decision_us) and all(np.isfinite(gaps))
    b_law = Recorder()
    run_episode(build_episode(sc, 0), b_law, run_rng(0))
    assert [e["gap"] for e in b_law.extras] == gaps  # the noise is the world's seeded stream


@pytest.mark.parametrize(
    ("data", "fragment"),
    [
        (scene({"speed": 0.5, "radius": 2.0}, sensor="sonar9"), "unknown sensor plug-in 'sonar9'"),
        (scene({"speed": -1.0, "radius": 2.0}), "speed and radius must be > 0"),
        (scene({"speed": 0.5}), "radius"),
    ],
)
def test_bad_plugin_names_and_params_are_one_line(data: dict[str, Any], fragment: str) -> None:
    with pytest.raises(ScenarioError) as err:
        scenario_from_dict(data)
    assert fragment in str(err.value) and "\n" not in str(err.value)


def test_unknown_motion_plugin_is_named() -> None:
    data = scene({})
    data["obstacles"][0]["motion"]["name"] = "teleport"
    with pytest.raises(ScenarioError, match="unknown motion plug-in 'teleport'"):
        scenario_from_dict(data)


def test_a_plugin_may_not_take_a_builtin_name(
    plugins: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    plugins[motion.MOTION_GROUP].append(FakeEntryPoint("constant", Circling))
    with pytest.raises(RuntimeError, match=r"'constant'.*already registered"):
        motion.motion_plugins()
    plugins[sensors.SENSOR_GROUP].append(FakeEntryPoint("lidar", nearest_gap))
    with pytest.raises(RuntimeError, match=r"'lidar'.*already registered"):
        sensors.sensor_plugins()
