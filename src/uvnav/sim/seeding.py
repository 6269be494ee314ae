"""Independent random streams of one episode, derived from its integer seed.

The world (obstacle motions, drawn when a scenario is built) and the run (controller and sensor
noise, inside :func:`uvnav.sim.run_episode`) use different streams of the same seed, so that e.g.
obstacle 0 and the controller never share random numbers, while "same scenario + same seed = same
trajectory" still holds bit for bit.
"""

from __future__ import annotations

import numpy as np

# non-zero: SeedSequence([seed, 0]) is the same stream as SeedSequence(seed)
_WORLD, _RUN = 1, 2


def world_rng(seed: int) -> np.random.Generator:
    """Generator for everything the scenario draws when an episode is built."""
    return np.random.default_rng([int(seed), _WORLD])


def run_rng(seed: int) -> np.random.Generator:
    """Generator to hand to :func:`uvnav.sim.run_episode` for the episode ``seed``."""
    return np.random.default_rng([int(seed), _RUN])
