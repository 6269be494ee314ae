"""Chapter-4 scenes: the built-ins run collision-free, the Fig. 4.2(b) trap is never entered, the
generator is seeded and keeps the chapter's assumptions, bad files give one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.controllers.base import make_law
from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.uuv2d import (
    UUV2D_GENERATORS,
    list_uuv2d_builtin,
    load_uuv2d_scenario,
    random_ch4_hard_scenario,
    random_ch4_scenario,
    uuv2d_from_dict,
)
from uvnav.sim.run import run_episode

THESIS = [
    "thesis-ch4-fig4-2b-trap",
    "thesis-ch4-fig4-7-approach",
    "thesis-ch4-fig4-8-decision",
    "thesis-ch4-fig4-9-whole-run",
]


def test_builtins_are_listed() -> None:
    assert list_uuv2d_builtin() == THESIS


@pytest.mark.parametrize(
    "name", ["thesis-ch4-fig4-2b-trap", "thesis-ch4-fig4-7-approach", "thesis-ch4-fig4-9-whole-run"]
)
def test_thesis_scene_is_collision_free_and_reaches_e(name: str) -> None:
    sc = load_uuv2d_scenario(name)
    res = run_episode(
        sc.to_setup(),
        make_law(sc.controller.name, vehicle="uuv2d"),
        np.random.default_rng(0),
        record=False,
    )
    assert res.status == "success"
    assert not res.metrics.collision and res.metrics.min_clearance is not None
    assert res.metrics.min_clearance > 0.05
    assert res.metrics.limit_violations == 0
    assert not res.flags["entered_forbidden"]


def test_trap_scene_is_a_real_trap_and_is_never_entered() -> None:
    sc = load_uuv2d_scenario("thesis-ch4-fig4-2b-trap")
    setup = sc.to_setup()
    assert len(setup.forbidden) == 1
    # the straight run from I to E crosses the inner space through the mouth
    inner = setup.forbidden[0]
    assert np.hypot(*(inner.mean(axis=0) - np.array([5.0, 5.0]))) < 1e-9
    res = run_episode(
        setup, make_law("zhang2022-uuv2d-v1", vehicle="uuv2d"), np.random.default_rng(1)
    )
    assert res.trajectory is not None
    poses = res.trajectory.poses[:, :2]
    # never inside the inner disc (radius 1.1 about (5, 5)), not even its mouth
    assert np.hypot(poses[:, 0] - 5.0, poses[:, 1] - 5.0).min() > 1.1 + 0.2
    assert not res.flags["entered_forbidden"] and res.status == "success"


def test_generator_is_seeded_and_keeps_the_assumptions() -> None:
    assert "random-ch4" in UUV2D_GENERATORS
    a, b = random_ch4_scenario(7), load_uuv2d_scenario("random-ch4:7")
    assert a.model_dump() == b.model_dump()
    counts = set()
    for seed in range(6):
        sc = random_ch4_scenario(seed)
        shapes = sc.shapes()
        counts.add(len(shapes))
        assert 1 <= len(shapes) <= 5
        centres = np.array([s.centre for s in shapes])
        radii = np.array([s.bounding_radius for s in shapes])
        for i in range(len(shapes)):
            for j in range(i):
                assert np.hypot(*(centres[i] - centres[j])) - radii[i] - radii[j] >= 1.0 - 1e-9
            assert all(0.05 <= s.max_rate <= 0.3 for s in shapes)
    assert len(counts) >= 3
    assert random_ch4_scenario(3, n_obstacles=5).obstacles.__len__() == 5


def test_hard_generator_is_seeded_and_keeps_the_assumptions() -> None:
    """random-ch4-hard: 2-6 bodies, faster deformation, translation below the vehicle's speed,
    bodies never closer than the narrow gap at any time of the episode, I and E kept clear."""
    a, b = random_ch4_hard_scenario(5), load_uuv2d_scenario("random-ch4-hard:5")
    assert a.model_dump() == b.model_dump()
    times = np.linspace(0.0, a.t_max, 301)
    moving = 0
    for seed in range(4):
        sc = random_ch4_hard_scenario(seed)
        shapes = sc.shapes()
        assert 2 <= len(shapes) <= 6
        for s in shapes:
            speed = float(np.hypot(*s.velocity))
            assert 0.3 <= s.max_rate <= 0.6 and speed <= 0.3 + 1e-3
            assert s.max_rate + speed < sc.vehicle.v_max  # slower than the vehicle
            moving += speed > 0
        paths = np.array([[s.centre_at(t) for t in times] for s in shapes])  # (n, T, 2)
        radii = np.array([s.bounding_radius for s in shapes])
        for i in range(len(shapes)):
            for end in (sc.vehicle.start, sc.vehicle.goal):
                gap_end = np.hypot(*(paths[i] - np.asarray(end)).T).min() - radii[i]
                assert gap_end >= 1.0 - 1e-6
            for j in range(i):
                gap = np.hypot(*(paths[i] - paths[j]).T).min() - radii[i] - radii[j]
                assert gap >= 2 * (sc.vehicle.radius + 0.05) - 1e-6
    assert moving >= 4


@pytest.mark.parametrize(
    ("data", "where"),
    [
        ({"kind": "uuv2d", "name": "x"}, "vehicle"),
        (
            {
                "kind": "uuv2d",
                "name": "x",
                "vehicle": {"start": [0, 0], "goal": [1, 1], "v_max": -1, "u_max": 1},
            },
            "vehicle.v_max",
        ),
        (
            {
                "kind": "uuv2d",
                "name": "x",
                "vehicle": {"start": [0, 0], "goal": [5, 5], "v_max": 1, "u_max": 1},
                "obstacles": [
                    {"type": "deforming", "centre": [0, 0], "area": 1.0, "max_rate": 0.1}
                ],
            },
            "vehicle.start",
        ),
        (
            {
                "kind": "uuv2d",
                "name": "x",
                "speed": 3,
                "vehicle": {"start": [0, 0], "goal": [5, 5], "v_max": 1, "u_max": 1},
            },
            "speed",
        ),
        (
            {
                "kind": "uuv2d",
                "name": "x",
                "vehicle": {"start": [0, 0], "goal": [5, 5], "v_max": 1, "u_max": 1},
                "obstacles": [{"type": "trap", "centre": [3, 3], "mouth": 5.0}],
            },
            "obstacles.0.mouth",
        ),
    ],
)
def test_bad_input_is_one_line_naming_the_field(data: dict, where: str) -> None:
    with pytest.raises(ScenarioError) as err:
        uuv2d_from_dict(data, "bad.yaml")
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("bad.yaml") and where in msg


def test_unknown_name_is_a_scenario_error() -> None:
    with pytest.raises(ScenarioError, match="thesis-ch4-fig4-7-approach"):
        load_uuv2d_scenario("no-such-scene")
    with pytest.raises(ScenarioError, match="seed"):
        load_uuv2d_scenario("random-ch4:x")
