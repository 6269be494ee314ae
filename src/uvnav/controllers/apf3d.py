"""``apf3d-v1``: artificial potential field for the 3D vehicle (baseline, not in the thesis).

Reference: O. Khatib, "Real-time obstacle avoidance for manipulators and mobile robots", IJRR 5(1),
1986 (FIRAS repulsion), in 3D.  The desired direction is the sum of a unit attraction toward E and,
for every sensed obstacle within ``influence`` rho_0 [m], the repulsion
``k_rep (1/rho - 1/rho_0) / rho^2`` along (c_R - r_min) / rho, where rho is the sensed distance
(3.8) less the robot radius.  A small tangential term (the repulsion turned about the horizontal
by the side the goal lies on) lets the robot slide round a body instead of stopping in the local
minimum in front of it.  The heading turns toward that direction at the bounded rate
(u_R orthogonal to a_R), with V_R = V_max scaled by the cosine of the heading error.  It uses
only the sensed nearest points (no velocities).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar, cast

import numpy as np

from uvnav.controllers.base import ControllerInfo, check_params, register
from uvnav.controllers.base3d import Vehicle3DController
from uvnav.dynamics.vehicle3d import Vehicle3DCommand
from uvnav.sensors.sensing3d import Observation3D


@dataclass(frozen=True)
class APF3DParams:
    """Parameters of ``apf3d-v1``.

    Attributes:
        influence: rho_0, distance beyond which an obstacle does not repel [m].
        k_rep: repulsion gain [m^2].
        k_tan: tangential (sliding) gain relative to the repulsion.
    """

    influence: float = 2.5
    k_rep: float = 2.0
    k_tan: float = 0.5

    def __post_init__(self) -> None:
        check_params(self, positive=("influence", "k_rep"), non_negative=("k_tan",))


class APF3D(Vehicle3DController):
    """3D potential field (see the module docstring)."""

    name: ClassVar[str] = "apf3d-v1"

    def __init__(self, params: APF3DParams | None = None) -> None:
        super().__init__()
        self.p = params or APF3DParams()

    def act(self, obs: Observation3D) -> Vehicle3DCommand:
        period = self.decision_period(obs.time)
        gap = self._goal - obs.position
        dist = float(np.linalg.norm(gap))
        if dist < 1e-9:
            return Vehicle3DCommand(0.0, np.zeros(3))
        att = gap / dist
        force = att.copy()
        active = False
        for rd in obs.obstacles:
            rho = max(rd.distance - self._spec.radius, 1e-3)
            if rho >= self.p.influence:
                continue
            away = obs.position - rd.nearest_point
            n = float(np.linalg.norm(away))
            away = away / n if n > 1e-9 else -att
            mag = self.p.k_rep * (1.0 / rho - 1.0 / self.p.influence) / (rho * rho)
            tangent = att - float(att @ away) * away
            nt = float(np.linalg.norm(tangent))
            tangent = tangent / nt if nt > 1e-9 else np.cross(away, [0.0, 0.0, 1.0])
            force += mag * (away + self.p.k_tan * tangent)
            active = True
        self._mode = "M2" if active else "M1"
        if not active:
            return self.approach(obs, period)
        nf = float(np.linalg.norm(force))
        direction = force / nf if nf > 1e-12 else att
        cos_e = float(np.clip(direction @ obs.heading, -1.0, 1.0))
        v = self._spec.v_max * max(cos_e, 0.1)
        return self.steer(obs, direction, v, period)


register(
    ControllerInfo(
        name=APF3D.name,
        factory=cast("Callable[..., Any]", APF3D),
        params_type=APF3DParams,
        summary="3D artificial potential field with tangential sliding (baseline)",
        reference="Khatib, IJRR 1986",
        vehicle="vehicle3d",
    )
)
