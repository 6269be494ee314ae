"""Layer 0: pure math on numpy arrays (angles, tangents, polygon and disc kernels)."""

from uvnav.geometry.angles import (
    heading_vector,
    signed_angle,
    vector_angle,
    wrap_scalar,
    wrap_to_pi,
)
from uvnav.geometry.polygons import (
    angular_extent,
    edge_soup,
    nearest_on_polygons,
    polygon_area,
    polygon_centroid,
    polygon_nearest,
    ray_polygon_hit,
    rays_circles_hit,
    rays_segments_hit,
    segment_intersects_polygon,
    transform_points,
)
from uvnav.geometry.tangents import CircleTangents, circle_tangents, disc_silhouette_angles

__all__ = [
    "CircleTangents",
    "angular_extent",
    "circle_tangents",
    "disc_silhouette_angles",
    "edge_soup",
    "heading_vector",
    "nearest_on_polygons",
    "polygon_area",
    "polygon_centroid",
    "polygon_nearest",
    "ray_polygon_hit",
    "rays_circles_hit",
    "rays_segments_hit",
    "segment_intersects_polygon",
    "signed_angle",
    "transform_points",
    "vector_angle",
    "wrap_scalar",
    "wrap_to_pi",
]
