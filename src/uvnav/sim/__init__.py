"""Layer 4: the worlds of every vehicle (stepped by :func:`uvnav.core.run_loop`), collision checks,
termination, recorder probes and metrics."""

from uvnav.sensors.config import LidarConfig, SensingConfig
from uvnav.sim.metrics import METRIC_NAMES, EpisodeMetrics
from uvnav.sim.recorder import Trajectory
from uvnav.sim.run import run_episode
from uvnav.sim.seeding import run_rng, world_rng
from uvnav.sim.setup import EpisodeResult, EpisodeSetup

__all__ = [
    "METRIC_NAMES",
    "EpisodeMetrics",
    "EpisodeResult",
    "EpisodeSetup",
    "LidarConfig",
    "SensingConfig",
    "Trajectory",
    "run_episode",
    "run_rng",
    "world_rng",
]
