"""The Chapter 6 pipeline (:mod:`uvnav.driving.pipeline`): a DAgger round's data and the
throttle modes of the CNN policy."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("gymnasium")

from uvnav.driving.dataset import read_log
from uvnav.driving.pipeline import dagger_collect
from uvnav.learning import PilotNetConfig
from uvnav.learning.pilotnet import build_pilotnet


def test_dagger_round_appends_expert_labelled_rows(tmp_path: Path) -> None:
    import torch

    torch.manual_seed(0)
    model = build_pilotnet(PilotNetConfig()).eval()
    rows = dagger_collect(model, tmp_path, [4], round_id=1, max_steps=40, record_every=4)
    assert rows == 10
    log = read_log(tmp_path)
    assert len(log) == 10 and all("d1_00004" in p.name for p in log.center)
    assert np.all(np.abs(log.steering) <= 1.0) and np.all(np.abs(log.throttle) <= 1.0)
    # the first state is the start of the track, where the expert's label is near straight
    assert abs(log.steering[0]) < 0.3
    # the side images carry the expert's command at the shifted poses: from 1.5 m left of the
    # car, steer more to the right (+), and the reverse
    assert log.steering_left is not None and log.steering_right is not None
    assert log.steering_left[0] > log.steering[0] + 0.05 > log.steering_right[0] + 0.1


def test_throttle_modes_of_the_cnn_policy() -> None:
    """learned-speed = the expert's P law on the network's target speed; modes match the head."""
    import torch

    from uvnav.driving.pipeline import cnn_policy, default_learned_mode
    from uvnav.driving.sim import Telemetry

    torch.manual_seed(0)
    net = PilotNetConfig(height=48, width=96, second_output="target_speed")
    model = build_pilotnet(net).eval()
    with torch.no_grad():  # the second output is 0.8 whatever the image: 0.8 * 50 = 40 m/s
        model.head[-1].weight[1].zero_()
        model.head[-1].bias[1] = 0.8
    frame = np.zeros((48, 96, 3), dtype=np.uint8)

    def tel(v: float) -> Telemetry:
        return Telemetry(0, 0.0, 0.0, 0.0, v, 0.0, 0.0, 0, 0, 10, False)

    assert default_learned_mode(model) == "learned-speed"
    act, on_reset = cnn_policy(model, throttle="learned-speed")
    assert on_reset is None
    assert act(frame, tel(36.0))[1] == pytest.approx(0.15 * (40.0 - 36.0))
    assert act(frame, tel(45.0))[1] == pytest.approx(0.15 * (40.0 - 45.0))  # brakes above it
    assert act(frame, tel(0.0))[1] == 1.0  # clipped
    slow, _ = cnn_policy(model, throttle="learned-speed", speed_factor=0.5)
    assert slow(frame, tel(15.0))[1] == pytest.approx(0.15 * (20.0 - 15.0))
    capped, _ = cnn_policy(model, throttle="learned-speed", max_speed=32.0)
    assert capped(frame, tel(30.0))[1] == pytest.approx(0.15 * (32.0 - 30.0))
    pi, reset = cnn_policy(model, throttle="pi", set_speed=35.0)
    assert reset is not None and pi(frame, tel(10.0))[1] > 0 and pi(frame, tel(60.0))[1] < 0
    with pytest.raises(ValueError, match="learned-speed"):
        cnn_policy(model, throttle="learned")
    with pytest.raises(ValueError, match="throttle head"):
        cnn_policy(build_pilotnet(PilotNetConfig(height=48, width=96)), throttle="learned-speed")
    with pytest.raises(ValueError, match="speed_factor"):
        cnn_policy(model, throttle="learned-speed", speed_factor=0.0)
    with pytest.raises(ValueError, match="must be one of"):
        cnn_policy(model, throttle="turbo")  # type: ignore[arg-type]
