"""3D scenario schema, loader hook (dim: 3), built-ins and the random-ch3 generator."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from uvnav.obstacles.motion3d import ObstacleState3D
from uvnav.scenarios import ScenarioError, list_builtin, load_scenario, scenario_from_dict
from uvnav.scenarios.generators import GENERATORS
from uvnav.scenarios.schema3d import Scenario3D

BASE = {
    "name": "t",
    "dim": 3,
    "robot": {"start": [0, 0, 0], "goal": [10, 0, 0], "v_max": 1.0, "u_max": 1.0},
    "obstacles": [
        {"body": {"sphere": 1.0}, "start": {"position": [5, 0, 0]},
         "motion": {"type": "constant", "velocity": [0, 0.2, 0]}},
    ],
}  # fmt: skip


def _err(data: dict) -> str:
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(data, "scene.yaml")
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("scene.yaml")
    return msg


def test_builtin_thesis_ch3_scenes_load_as_3d() -> None:
    names = [n for n in list_builtin() if n.startswith("thesis-ch3")]
    assert len(names) == 3
    for n in names:
        assert isinstance(load_scenario(n), Scenario3D)


def test_bad_3d_inputs_get_one_line_errors_naming_the_field() -> None:
    d = copy.deepcopy(BASE)
    d["robot"]["heading"] = [1.0, 1.0, 0.0]
    assert "robot.heading" in _err(d) and "unit vector" in _err(d)
    d = copy.deepcopy(BASE)
    d["obstacles"][0]["motion"]["velocity"] = [1.5, 0, 0]
    assert "(3.9)" in _err(d)
    d = copy.deepcopy(BASE)
    d["obstacles"][0]["body"] = {
        "mesh": {
            "vertices": [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]],
            "faces": [[0, 1, 2], [0, 1, 3], [1, 2, 3], [0, 2, 3]],
        }
    }
    assert "degenerate" in _err(d)
    d = copy.deepcopy(BASE)
    d["obstacles"][0]["start"]["position"] = [0.5, 0, 0]
    assert "robot.start" in _err(d)
    d = copy.deepcopy(BASE)
    d["robot"]["wings"] = 2
    assert "wings" in _err(d)


def test_random_ch3_is_registered_seeded_and_valid() -> None:
    assert "random-ch3" in GENERATORS
    a = load_scenario("random-ch3:11")
    b = load_scenario("random-ch3:11")
    c = load_scenario("random-ch3:12")
    assert isinstance(a, Scenario3D) and a == b and a != c
    assert 2 <= len(a.obstacles) <= 4
    for ob in a.obstacles:
        assert ob.motion.bounds()[0] < a.robot.v_max and ob.motion.bounds()[1] < a.robot.u_max


def test_random_ch3_periodic_is_the_default_scene_with_weaving_bodies() -> None:
    """``motion="periodic"`` keeps the default scene's bodies, poses and mean motion (its own
    draws come from another generator) and bounds the speed below V_max (3.9)."""
    assert "random-ch3-periodic" in GENERATORS
    for seed in (0, 5, 192):
        base = load_scenario(f"random-ch3:{seed}")
        assert GENERATORS["random-ch3"](seed, motion="ar") == base  # the default, explicitly
        per = load_scenario(f"random-ch3-periodic:{seed}")
        assert per.name == f"random-ch3-periodic:{seed}" and per == load_scenario(per.name)
        assert len(per.obstacles) == len(base.obstacles)
        for a, b in zip(base.obstacles, per.obstacles, strict=True):
            assert a.body == b.body and a.start == b.start
            m = b.motion
            assert m.type == "periodic" and m.v_mean == a.motion.v_mean
            assert 6.0 <= m.osc_period <= 12.0 and m.damping < 1.0 and m.v_sigma > 0.0
            osc = np.array([m.amp_cos, m.amp_sin])
            assert np.allclose(osc @ np.array(m.v_mean), 0.0, atol=1e-3)  # across the motion
            speed = np.hypot(np.linalg.norm(m.v_mean), np.linalg.norm(m.amp_cos))
            assert speed < m.v_max < per.robot.v_max
            assert np.linalg.norm(m.rotation_rate) < per.robot.u_max  # (3.10)
        # along an episode the sampled speeds stay within the bound and do vary
        setup = per.build(seed)
        st = ObstacleState3D(np.zeros(3))
        v = np.array([setup.obstacles[0].motion.rates(float(k), st)[0] for k in range(60)])
        assert np.linalg.norm(v, axis=1).max() <= per.obstacles[0].motion.v_max + 1e-12
        assert np.ptp(v, axis=0).max() > 0.1


def test_periodic_motion_entries_are_checked() -> None:
    d = copy.deepcopy(BASE)
    d["obstacles"][0]["motion"] = {"type": "periodic", "v_mean": [0, 0.2, 0], "osc_period": 8,
                                   "amp_cos": [0.1, 0, 0], "v_max": 1.2}  # fmt: skip
    assert "(3.9)" in _err(d)
    d["obstacles"][0]["motion"]["v_max"] = 0.5
    d["obstacles"][0]["motion"]["damping"] = 1.5
    assert "damping" in _err(d)
    d["obstacles"][0]["motion"]["damping"] = 0.9
    assert isinstance(scenario_from_dict(d, "scene.yaml"), Scenario3D)


def test_2d_entry_points_refuse_or_skip_3d_scenes_clearly() -> None:
    from uvnav.scenarios import build_episode, check_constraints

    sc = load_scenario("thesis-ch3-fig3-5-single-cycle")
    assert check_constraints(sc) == []  # (3.9)-(3.10) were checked on loading
    with pytest.raises(ScenarioError, match="3D simulator"):
        build_episode(sc, 0)  # type: ignore[arg-type]
