"""How a 2D robot senses (the configuration of :class:`~uvnav.sensors.suite2d.Sensors2D`): the
range, known or estimated body rates, a lidar, plug-in sensors and where the bodies' readings
come from."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np


@dataclass(frozen=True)
class LidarConfig:
    """Lidar on the robot: ``n_rays`` beams over ``fov`` [rad], ``max_range`` [m], noise [m]."""

    n_rays: int = 72
    max_range: float = 5.0
    fov: float = 2.0 * np.pi
    noise_std: float = 0.0
    dropout: float = 0.0


@dataclass(frozen=True)
class SensingConfig:
    """How observations are made.

    Attributes:
        sensing_range: obstacles farther than this [m] are not reported.
        velocities: ``"known"`` gives true v_i, u_i (the thesis's assumption); ``"estimated"``
            gives finite differences of the sensed centre and outline
            (:class:`FiniteDifferenceEstimator`).
        position_noise: std [m] of the noise on the observed centre when estimating.
        lidar: optional range scanner.
        plugins: ``(name, params)`` of plug-in sensors (:mod:`uvnav.sensors.plugins`), read
            after the built-in sensors from the same sensing generator.
        bodies: where the law's readings of the bodies come from: ``"exact"`` (each body's
            exact geometry within the range) or ``"lidar"`` (the bodies the lidar scan shows,
            :mod:`uvnav.sensors.scan_bodies`: needs ``lidar`` and estimated velocities; a law
            that is an oracle still gets the exact readings).
    """

    sensing_range: float = 5.0
    velocities: Literal["known", "estimated"] = "known"
    position_noise: float = 0.0
    lidar: LidarConfig | None = None
    plugins: tuple[tuple[str, dict[str, Any]], ...] = ()
    bodies: Literal["exact", "lidar"] = "exact"

    def __post_init__(self) -> None:
        if self.bodies == "lidar" and (self.lidar is None or self.velocities != "estimated"):
            raise ValueError("bodies sensed by lidar need a lidar and estimated velocities")
