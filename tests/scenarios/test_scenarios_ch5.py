"""Chapter 5 scenarios: built-ins, one-line errors, the seeded random generator."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from uvnav.scenarios.ch5 import (
    build_uuv3d,
    list_ch5_builtin,
    load_ch5_scenario,
    random_ch5_end_clearance,
    random_ch5_min_spacing,
    random_ch5_scenario,
)
from uvnav.scenarios.errors import ScenarioError


def test_builtins_are_the_three_thesis_scenes() -> None:
    assert list_ch5_builtin() == ["thesis-ch5-scene1", "thesis-ch5-scene2", "thesis-ch5-scene3"]
    counts = [len(load_ch5_scenario(n).obstacles) for n in list_ch5_builtin()]
    assert counts == [1, 1, 2]
    s2 = build_uuv3d(load_ch5_scenario("thesis-ch5-scene2"))
    body = s2.obstacles[0]
    assert body.inner_space is not None
    # the slot is narrower than the vehicle
    assert 2 * body.inner_space[2][1] < 2 * s2.spec.radius


def test_bad_field_is_one_line_naming_file_and_field(tmp_path: Path) -> None:
    f = tmp_path / "bad.yaml"
    f.write_text("name: x\nrobot: {start: [0,0,0], heading: [1,0,0], goal: [9,0,0], v_max: -1}\n")
    with pytest.raises(ScenarioError) as exc:
        load_ch5_scenario(str(f))
    msg = str(exc.value)
    assert "\n" not in msg and "bad.yaml" in msg and "robot.v_max" in msg
    f.write_text(
        "name: x\nrobot: {start: [0,0,0], heading: [1,0,0], goal: [9,0,0]}\n"
        "obstacles: [{type: star, centre: [1,1,1], base_radius: 1, delta_max: 0.5}]\n"
    )
    with pytest.raises(ScenarioError, match=r"obstacles\.0\.delta_max"):
        load_ch5_scenario(str(f))
    with pytest.raises(ScenarioError, match="seed"):
        load_ch5_scenario("random-ch5:x")
    with pytest.raises(ScenarioError, match="no such file"):
        load_ch5_scenario("nope.yaml")


def test_random_generator_is_seeded_and_within_assumptions() -> None:
    counts = []
    for seed in range(40):
        a = random_ch5_scenario(seed)
        assert a == random_ch5_scenario(seed)
        assert a == load_ch5_scenario(f"random-ch5:{seed}")
        goal = np.asarray(a.robot.goal)
        assert 26.0 <= float(np.linalg.norm(goal)) <= 40.0
        direction = goal / np.linalg.norm(goal)
        centres = [np.asarray(o.centre) for o in a.obstacles]
        radii = [o.base_radius for o in a.obstacles]
        counts.append(len(centres))
        for i, (c, r) in enumerate(zip(centres, radii, strict=True)):
            clear = random_ch5_end_clearance(r)
            assert np.linalg.norm(c) >= clear and np.linalg.norm(goal - c) >= clear
            # it blocks the straight line: sideways offset at most its base radius
            assert np.linalg.norm(c - (c @ direction) * direction) <= r + 1e-9
            for d, rd in zip(centres[i + 1 :], radii[i + 1 :], strict=True):
                assert np.linalg.norm(c - d) >= random_ch5_min_spacing(r, rd) - 1e-9
    # every count the generator draws is built (v1's fixed 12 m spacing never fitted three)
    assert set(counts) == {1, 2, 3}
    three = random_ch5_scenario(0, n_obstacles=3)
    assert len(three.obstacles) == 3
    with pytest.raises(ValueError, match=r"1\.\.3"):
        random_ch5_scenario(0, n_obstacles=4)
    assert random_ch5_scenario(1) != random_ch5_scenario(2)


def test_dense_family_is_closer_than_the_assumptions_and_loads_by_name() -> None:
    counts = set()
    for seed in range(20):
        a = load_ch5_scenario(f"random-ch5-dense:{seed}")
        assert a == random_ch5_scenario(seed, dense=True)
        assert a.name == f"random-ch5-dense:{seed}"
        centres = [np.asarray(o.centre) for o in a.obstacles]
        radii = [o.base_radius for o in a.obstacles]
        counts.add(len(centres))
        gaps = [
            np.linalg.norm(c - d) - random_ch5_min_spacing(r, rd, dense=True)
            for c, d, r, rd in zip(centres, centres[1:], radii, radii[1:], strict=False)
        ]
        assert min(gaps) >= -1e-9
    assert counts == {2, 3, 4}
    # dense: 1 m between deformed surfaces instead of L + one turn radius (4 m): 3 m closer
    closer = random_ch5_min_spacing(1.0, 1.0) - random_ch5_min_spacing(1.0, 1.0, dense=True)
    assert closer == pytest.approx(3.0)
    with pytest.raises(ScenarioError, match="seed"):
        load_ch5_scenario("random-ch5-dense:x")
