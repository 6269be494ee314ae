"""Layer 1: obstacle bodies (discs, non-convex polygons) and their motion models."""

from uvnav.obstacles.batch import ObstacleBatch
from uvnav.obstacles.bodies import (
    Body,
    DiscBody,
    PolygonBody,
    radial_profile,
    rotation_boundary_growth,
)
from uvnav.obstacles.crowd import Crowd, OrcaPedestrian, OrcaWanderer, join_crowds
from uvnav.obstacles.motion import (
    ConstantVelocity,
    MotionModel,
    ObstacleState,
    RandomTurn,
    Replay,
    Waypoints,
)
from uvnav.obstacles.obstacle import FieldTemplate, NearestQuery, Obstacle, ObstacleField
from uvnav.obstacles.social_force import SocialForcePedestrian

__all__ = [
    "Body",
    "ConstantVelocity",
    "Crowd",
    "DiscBody",
    "FieldTemplate",
    "MotionModel",
    "NearestQuery",
    "Obstacle",
    "ObstacleBatch",
    "ObstacleField",
    "ObstacleState",
    "OrcaPedestrian",
    "OrcaWanderer",
    "PolygonBody",
    "RandomTurn",
    "Replay",
    "SocialForcePedestrian",
    "Waypoints",
    "join_crowds",
    "radial_profile",
    "rotation_boundary_growth",
]
