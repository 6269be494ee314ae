"""The scene catalog (issue 16): kinds from file content, one generator registry with plug-ins,
duplicates refused."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import uvnav.core as core
import uvnav.scenarios.catalog as catalog
from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.generators import random_ch2_scenario


class FakeEntryPoint:
    def __init__(self, name: str, obj: Any) -> None:
        self.name, self.value, self._obj = name, f"plugin:{name}", obj

    def load(self) -> Any:
        return self._obj


@pytest.fixture
def plugins(monkeypatch: pytest.MonkeyPatch) -> Any:
    def install(**objs: Any) -> None:
        eps = [FakeEntryPoint(n.replace("_", "-"), o) for n, o in objs.items()]
        monkeypatch.setattr(
            core, "entry_points", lambda group: eps if group == catalog.GENERATOR_GROUP else []
        )
        core.load_plugins.cache_clear()

    yield install
    core.load_plugins.cache_clear()


@pytest.mark.parametrize(
    ("data", "kind"),
    [
        ({"kind": "uuv2d"}, "uuv2d"),
        ({"robots": []}, "multi2d"),
        ({"dim": 3, "sonar": {}}, "uuv3d"),
        ({"dim": 3}, "nav3d"),
        ({"dim": 2}, "nav2d"),
        ({}, "nav2d"),
        ({"kind": "boat"}, "nav2d"),
    ],
)
def test_kind_is_read_from_the_content(data: dict[str, Any], kind: str) -> None:
    assert catalog.infer_kind(data) == kind


def test_plugin_generator_is_a_generator_like_the_builtins(plugins: Any) -> None:
    def lanes(seed: int, n_obstacles: int = 2) -> Any:
        return random_ch2_scenario(seed, n_obstacles=n_obstacles)

    plugins(my_lanes=lanes)
    assert catalog.generators()["my-lanes"].name == "nav2d"
    res = catalog.resolve("my-lanes:4")
    assert res.seed == 4 and len(res.scenario.obstacles) == 2
    assert len(catalog.generate("my-lanes", 4, {"n_obstacles": 3}).scenario.obstacles) == 3
    with pytest.raises(ScenarioError, match="params"):
        catalog.generate("my-lanes", 4, {"bogus": 1})


def test_plugin_returning_another_kind_is_refused(plugins: Any) -> None:
    def wrong(seed: int) -> Any:
        return random_ch2_scenario(seed)

    wrong.scene_kind = "uuv2d"  # type: ignore[attr-defined]
    plugins(wrong_kind=wrong)
    with pytest.raises(ScenarioError, match="not a Uuv2dScenario"):
        catalog.resolve("wrong-kind:1")


def test_a_taken_generator_name_is_refused(plugins: Any) -> None:
    plugins(random_ch2=random_ch2_scenario)
    with pytest.raises(RuntimeError, match=r"'random-ch2'.*already registered"):
        catalog.generators()


def test_a_directory_or_a_binary_file_is_one_line(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match="is a directory"):
        catalog.resolve(str(tmp_path))
    binary = tmp_path / "x.yaml"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(ScenarioError) as err:
        catalog.resolve(str(binary))
    assert "\n" not in str(err.value)
