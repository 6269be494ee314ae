"""Layer 1: obstacle bodies (discs, non-convex polygons) and their motion models."""

from uvnav.obstacles.batch import ObstacleBatch
from uvnav.obstacles.bodies import (
    Body,
    DiscBody,
    PolygonBody,
    radial_profile,
    rotation_boundary_growth,
)
from uvnav.obstacles.motion import (
    ConstantVelocity,
    MotionModel,
    ObstacleState,
    RandomTurn,
    Replay,
    Waypoints,
)
from uvnav.obstacles.obstacle import FieldTemplate, NearestQuery, Obstacle, ObstacleField

__all__ = [
    "Body",
    "ConstantVelocity",
    "DiscBody",
    "FieldTemplate",
    "MotionModel",
    "NearestQuery",
    "Obstacle",
    "ObstacleBatch",
    "ObstacleField",
    "ObstacleState",
    "PolygonBody",
    "RandomTurn",
    "Replay",
    "Waypoints",
    "radial_profile",
    "rotation_boundary_growth",
]
