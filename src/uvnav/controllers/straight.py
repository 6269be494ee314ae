"""``straight-v1``: drive at the target at V_max, ignoring obstacles (the floor for every metric).

It turns toward the goal with the bounded heading law of
:func:`uvnav.controllers.base.heading_rate_toward`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from uvnav.controllers.base import ControllerInfo, UnicycleController, heading_rate_toward, register
from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.geometry.angles import wrap_scalar
from uvnav.sensors.observation import Observation


@dataclass(frozen=True)
class StraightParams:
    """Parameters of ``straight-v1``.

    Attributes:
        slow_radius: distance to the goal [m] inside which speed falls linearly to 0
            (0 = never slow).
    """

    slow_radius: float = 0.0


class StraightController(UnicycleController):
    name: ClassVar[str] = "straight-v1"

    def __init__(self, params: StraightParams | None = None) -> None:
        super().__init__()
        self.params = params or StraightParams()

    def act(self, obs: Observation) -> UnicycleCommand:
        period = self.decision_period(obs.time)
        to_goal = self._goal - obs.position
        err = wrap_scalar(float(np.arctan2(to_goal[1], to_goal[0])) - obs.heading)
        v = self._spec.v_max
        if self.params.slow_radius > 0:
            v *= min(1.0, float(np.hypot(*to_goal)) / self.params.slow_radius)
        return UnicycleCommand(v, heading_rate_toward(err, self._spec.u_max, period))


register(
    ControllerInfo(
        name="straight-v1",
        factory=StraightController,
        params_type=StraightParams,
        summary="Straight to the target at V_max, ignoring obstacles (metric floor).",
    )
)
