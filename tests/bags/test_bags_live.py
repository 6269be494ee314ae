"""``uvnav.bags.live``: the live episode's channels and its pacing at ``speed`` times real time
(the WebSocket side is tested end to end in ``tests/cli/test_cli_view.py``)."""

from __future__ import annotations

import pytest

pytest.importorskip("foxglove")
pytest.importorskip("mcap_ros2")

from uvnav.bags.live import FoxgloveEpisode
from uvnav.scenarios.catalog import resolve
from uvnav.scenarios.episodes import run_scene


class FakeClock:
    """A wall clock that moves only when slept on."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        assert seconds > 0.0
        self.now += seconds


@pytest.mark.parametrize("speed", [0.5, 4.0])
def test_steps_are_sent_at_speed_times_real_time(speed: float) -> None:
    clock = FakeClock()
    probe = FoxgloveEpisode(port=0, speed=speed, wait=False, clock=clock, sleep=clock.sleep)
    try:
        out = run_scene(resolve("random-ch2:3"), probes=[probe])
    finally:
        probe.stop()
    assert probe._start is not None
    first = probe._start[1]
    assert probe.last_t > first + 5.0
    assert clock.now == pytest.approx((probe.last_t - first) / speed)
    assert out.status == run_scene(resolve("random-ch2:3")).status


def test_a_multi_robot_scene_has_one_set_of_topics_per_robot() -> None:
    probe = FoxgloveEpisode(port=0, speed=1e6, wait=False)
    try:
        run_scene(resolve("antipodal:2"), probes=[probe])
    finally:
        probe.stop()
    leaves = ("odom", "cmd_vel", "mode", "scan")
    names = probe.names
    assert len(names) == 2 and all(names)
    expected = {"/tf", "/bodies"} | {f"/{n}/{leaf}" for n in names for leaf in leaves}
    assert set(probe.channels) == expected
    assert probe._seq[f"/{names[1]}/odom"] == probe._seq["/tf"] > 10


def test_speed_must_be_positive() -> None:
    with pytest.raises(ValueError, match=r"speed 0\.0: must be > 0"):
        FoxgloveEpisode(port=0, speed=0.0)
