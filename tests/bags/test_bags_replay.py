"""A rosbag2 written with ``rosbags`` (a lidar robot passing a moving disc, its odometry) replayed
through a law (``uvnav.bags.replay``): the commands are the law's own on the observations a
simulated lidar robot makes of the same scene."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

from bagmaker import GOAL, observations, robot_state, write_bag
from uvnav.bags.replay import BagError, read_bag, replay
from uvnav.controllers.base import make_law
from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.dynamics.vehicles import make_vehicle

STEPS = 40
ROBOT = UnicycleSpec(v_max=1.0, u_max=2.0, radius=0.3)


def _direct(law_name: str, obs: list) -> tuple[np.ndarray, list[str]]:
    """The law run on the simulated robot's own observations."""
    vehicle = make_vehicle("holonomic" if "holonomic" in law_name else "unicycle", ROBOT)
    law = make_law(law_name)
    law.reset(vehicle.spec, GOAL, np.random.default_rng(0))
    cmds, modes = [], []
    for o in obs:
        cmds.append(vehicle.pair(law.act(o)))
        modes.append(law.mode)
    return np.array(cmds), modes


@pytest.mark.parametrize(
    ("law_name", "storage"),
    [("zhang2019-holonomic-v2", "sqlite3"), ("zhang2019-holonomic-v2", "mcap"),
     ("zhang2019-v1", "sqlite3")],
)  # fmt: skip
def test_replayed_commands_are_the_laws_own(tmp_path: Path, law_name: str, storage: str) -> None:
    obs = observations(STEPS)
    bag = write_bag(tmp_path / "run", obs, storage)
    scans = read_bag(bag)
    assert len(scans.records) == STEPS and scans.skipped == 0
    result = replay(scans, law_name, {}, GOAL, ROBOT)
    want, modes = _direct(law_name, obs)
    # the bag holds float32 ranges and angles: equal to well below a millimetre per second
    np.testing.assert_allclose(result.law_commands, want, atol=1e-4)
    assert result.modes == modes
    assert list(result.bodies) == [len(o.obstacles) for o in obs]
    assert max(result.bodies) >= 1  # the disc was seen...
    straight = [np.allclose(c, want[0], atol=1e-3) for c in want]
    assert not all(straight)  # ...and changed what the law commands
    np.testing.assert_allclose(result.times, [o.time for o in obs], atol=1e-9)


def test_the_robot_columns_are_the_odometry(tmp_path: Path) -> None:
    obs = observations(10)
    scans = read_bag(write_bag(tmp_path / "run", obs))
    uni = replay(scans, "zhang2019-v1", {}, GOAL, ROBOT)
    holo = replay(scans, "zhang2019-holonomic-v2", {}, GOAL, ROBOT)
    for k, o in enumerate(obs):
        pose, (vx, _, wz) = robot_state(o.time)
        np.testing.assert_allclose(uni.poses[k], pose, atol=1e-12)
        np.testing.assert_allclose(uni.robot_commands[k], (vx, wz))  # forward speed, turn rate
        world = (vx * math.cos(pose[2]), vx * math.sin(pose[2]))
        np.testing.assert_allclose(holo.robot_commands[k], world)  # in the odometry frame
    assert uni.command_names[0].startswith("V_R") and holo.command_names[0].startswith("v_x")


def test_scans_before_the_first_odometry_are_skipped(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / "run", observations(5), odometry=False)
    with pytest.raises(BagError, match=r"no LaserScan on /scan after the first Odometry on /odom"):
        read_bag(bag)
