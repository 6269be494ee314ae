"""``uvnav bench --mcap-dir``: one readable MCAP file per episode the invocation runs, the
stored numbers the same as without it; none for episodes skipped on --resume."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

pytest.importorskip("mcap_ros2")

from mcap.reader import make_reader

from uvnav.bags.mcap import McapFolder, episode_file
from uvnav.bench.jobs import Job
from uvnav.bench.summary import TIMING_COLUMNS
from uvnav.cli.app import app

runner = CliRunner()

CAMPAIGN = """\
name: mcap-two
scenarios:
  - generator: random-ch2
    seeds: [3, 5]
controllers:
  - name: zhang2019-v1
"""

TOPICS = {"/tf", "/bodies", "/odom", "/cmd_vel", "/mode"}


def _bench(tmp_path: Path, db: str, *more: str) -> dict[str, Any]:
    campaign = tmp_path / "campaign.yaml"
    campaign.write_text(CAMPAIGN)
    args = ["bench", str(campaign), "--db", str(tmp_path / db), "--workers", "1", "--json"]
    result = runner.invoke(app, [*args, *more])
    assert result.exit_code == 0, result.output
    record: dict[str, Any] = json.loads(result.stdout)
    return record


def _summary(record: dict[str, Any]) -> list[dict[str, Any]]:
    return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in record["controllers"]]


def test_mcap_dir_writes_one_readable_file_per_episode_run(tmp_path: Path) -> None:
    folder = tmp_path / "episodes"
    with_files = _bench(tmp_path, "a.sqlite", "--mcap-dir", str(folder))
    files = sorted(p.name for p in folder.iterdir())
    assert files == [
        "random-ch2_0003__zhang2019-v1__3.mcap",
        "random-ch2_0004__zhang2019-v1__4.mcap",
    ]
    for name in files:
        with (folder / name).open("rb") as fh:
            reader = make_reader(fh)
            summary = reader.get_summary()
            assert summary is not None
            topics = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
            assert set(topics) == TOPICS
            assert topics["/odom"] == "nav_msgs/msg/Odometry"
            assert summary.statistics is not None and summary.statistics.message_count > 50
            meta = {r.name: dict(r.metadata) for r in reader.iter_metadata()}
            assert meta["uvnav"]["law"] == "zhang2019-v1"
    without = _bench(tmp_path, "b.sqlite")
    assert _summary(with_files) == _summary(without)  # the probe only observes

    again = tmp_path / "again"
    resumed = _bench(tmp_path, "a.sqlite", "--resume", "--mcap-dir", str(again))
    assert resumed["ran"] == 0 and resumed["skipped"] == 2
    assert list(again.iterdir()) == []


def test_mcap_dir_that_is_a_file_is_one_line(tmp_path: Path) -> None:
    target = tmp_path / "taken"
    target.write_text("x")
    campaign = tmp_path / "campaign.yaml"
    campaign.write_text(CAMPAIGN)
    args = ["bench", str(campaign), "--db", str(tmp_path / "c.sqlite"), "--mcap-dir", str(target)]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert result.output.strip().splitlines() == [
        f"error: --mcap-dir {target}: is a file; give a folder"
    ]
    assert not (tmp_path / "c.sqlite").exists()


def test_episode_file_names_are_sanitised() -> None:
    assert episode_file("random-ch2[speed=0.5]/0003", "zhang2019-v1", 7) == (
        "random-ch2_speed_0.5_0003__zhang2019-v1__7.mcap"
    )
    assert episode_file("../x y", "a/b", 0) == "x_y__a_b__0.mcap"


def test_no_probe_for_jobs_without_a_2d_scene(tmp_path: Path) -> None:
    factory = McapFolder(tmp_path)
    scene_3d = Job(controller="zhang2019-3d-v1", seed=0, scenario="thesis-ch3-several-obstacles")
    assert factory(scene_3d) == []
    assert list(tmp_path.iterdir()) == []
