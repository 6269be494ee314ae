"""Field types the 2D scene specs share: a planar point and an ordered box, both in metres."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import AfterValidator, Field

from uvnav.scenarios.limits import Coordinate

Point2 = Annotated[tuple[Coordinate, Coordinate], Field(description="[x, y] [m]")]
"""A planar point ``[x, y]`` [m]."""


def _ordered_box(value: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    if not (value[0] < value[2] and value[1] < value[3]):
        raise ValueError(f"need xmin < xmax and ymin < ymax (got {list(value)})")
    return value


#: a box ``[xmin, ymin, xmax, ymax]`` [m] with xmin < xmax and ymin < ymax
Box = Annotated[tuple[float, float, float, float], AfterValidator(_ordered_box)]


def heading_of(vector: np.ndarray, default: float) -> float:
    """Direction [rad] of ``vector``, or ``default`` for a (near) zero vector."""
    if float(np.hypot(vector[0], vector[1])) <= 1e-12:
        return default
    return float(np.arctan2(vector[1], vector[0]))
