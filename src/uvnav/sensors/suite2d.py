"""What a planar robot observes, as one part of the 2D worlds (:class:`Sensors2D`): the bodies
within its range (their exact geometry, or the bodies its lidar scan shows,
:mod:`uvnav.sensors.scan_bodies`), their rates (known, or estimated from noisy sensed positions,
:class:`~uvnav.prediction.FiniteDifferenceEstimator`), the lidar scan and the plug-in sensors
(:mod:`uvnav.sensors.plugins`), all from one sensing generator.

A world gives the part what only it knows: the exact readings of the bodies around the robot
(the one-robot world reads them from its bodies; the multi-robot world from its obstacles and
the other robots) and the field the lidar and the plug-ins see (built only when one of them
reads it).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.obstacle import ObstacleField
from uvnav.prediction.finite_difference import FiniteDifferenceEstimator
from uvnav.sensors.config import SensingConfig
from uvnav.sensors.exact import lidar_scan
from uvnav.sensors.observation import LidarScan, Observation, ObstacleReading
from uvnav.sensors.plugins import sensor_plugin
from uvnav.sensors.scan_bodies import ScanBodies


class Sensors2D:
    """One robot's sensors (module docstring).

    Args:
        config: what the robot senses (range, rates, lidar, plug-ins, bodies).
        rng: the sensing generator: the estimator's position noise, the lidar's noise and
            dropout, and the plug-ins draw from it, in the order they read.
    """

    def __init__(self, config: SensingConfig, rng: np.random.Generator) -> None:
        self.config = config
        self.rng = rng
        self.range = float(config.sensing_range)
        self.estimator: FiniteDifferenceEstimator | None = None
        self.scan_bodies: ScanBodies | None = None
        self.exact_only = False

    def reset(self, oracle: bool) -> None:
        """A new episode: an oracle law reads the exact bodies with their true rates; any
        other reads what its configuration says."""
        c = self.config
        self.estimator = (
            FiniteDifferenceEstimator(self.rng, c.position_noise)
            if c.velocities == "estimated" and not oracle
            else None
        )
        self.scan_bodies = ScanBodies() if c.bodies == "lidar" and not oracle else None
        #: an observation is the exact readings alone (nothing estimated or scanned, no lidar,
        #: no plug-in): a function of the world's state at the decision, drawing nothing from
        #: the generator and keeping nothing from one decision to the next
        self.exact_only = (
            self.estimator is None and self.scan_bodies is None and c.lidar is None
            and not c.plugins
        )  # fmt: skip

    @property
    def true_rates(self) -> bool:
        """Whether the readings carry the bodies' true rates (nothing estimated)."""
        return self.estimator is None

    def observe(
        self,
        t: float,
        pose: FloatArray,
        speed: float,
        goal: FloatArray,
        exact: Callable[[], tuple[ObstacleReading, ...]],
        field: Callable[[], ObstacleField],
    ) -> Observation:
        """The observation at time ``t`` [s] from ``pose`` ``[x, y, theta]`` (the robot's
        ``speed`` [m/s] and ``goal`` [m]); ``exact()`` gives the exact readings within the
        range, ``field()`` the bodies the lidar and the plug-ins see."""
        scan = None
        if self.scan_bodies is not None:  # the scan first: the readings are made from it
            scan = self.scan(pose, field())
            readings = self.scan_bodies.readings(t, pose, scan, self.range)
        else:
            readings = exact()
        if self.estimator is not None:
            readings = self.estimator.update(t, readings)
        if self.config.lidar is not None and scan is None:
            scan = self.scan(pose, field())
        plugins = self.config.plugins
        extras = (
            {
                name: sensor_plugin(name)(pose, field(), self.rng, **params)
                for name, params in plugins
            }
            if plugins
            else {}
        )
        return observation(t, pose, speed, goal, readings, scan, extras)

    def exact_observation(
        self, t: float, pose: FloatArray, speed: float, goal: FloatArray,
        readings: tuple[ObstacleReading, ...],
    ) -> Observation:  # fmt: skip
        """:meth:`observe` where the observation is the exact readings alone
        (:attr:`exact_only`): ``readings`` are the exact readings within the range."""
        return observation(t, pose, speed, goal, readings, None, {})

    def scan(self, pose: FloatArray, field: ObstacleField) -> LidarScan:
        """The lidar's scan of ``field`` from ``pose`` (noise and dropout from the sensing
        generator)."""
        lc = self.config.lidar
        assert lc is not None
        return lidar_scan(
            pose, field, self.rng, n_rays=lc.n_rays, max_range=lc.max_range, fov=lc.fov,
            noise_std=lc.noise_std, dropout=lc.dropout,
        )  # fmt: skip


def observation(
    t: float, pose: FloatArray, speed: float, goal: FloatArray,
    readings: tuple[ObstacleReading, ...], lidar: LidarScan | None, extras: dict[str, Any],
) -> Observation:  # fmt: skip
    """``Observation(time=t, pose=pose, ...)``, built without the frozen ``__init__`` (which sets
    each field through ``object.__setattr__``): the same object in a third of the time, for
    worlds that observe at every decision."""
    obs = _new(Observation)
    obs.__dict__.update(
        time=t, pose=pose, speed=speed, goal=goal, obstacles=readings, lidar=lidar, extras=extras
    )
    return obs


_new = object.__new__
