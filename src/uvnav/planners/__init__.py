"""Global planners (layer 3, pure): occupancy grids from static obstacles, Dijkstra, A*, D* Lite
and the visibility graph.  Thesis Ch. 1 §1.2 (review) and Ch. 8 (global plan + reactive law)."""

from uvnav.planners.dstar_lite import DStarLite
from uvnav.planners.grid import (
    OccupancyGrid,
    empty_grid,
    inflated_geometry,
    occupancy_grid,
    rasterize,
    safe_inflation,
)
from uvnav.planners.search import GridPath, astar, dijkstra, grid_edges, path_cost
from uvnav.planners.visibility import PolylinePath, grown_obstacles, visibility_path

__all__ = [
    "DStarLite",
    "GridPath",
    "OccupancyGrid",
    "PolylinePath",
    "astar",
    "dijkstra",
    "empty_grid",
    "grid_edges",
    "grown_obstacles",
    "inflated_geometry",
    "occupancy_grid",
    "path_cost",
    "rasterize",
    "safe_inflation",
    "visibility_path",
]
