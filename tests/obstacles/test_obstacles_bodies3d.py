"""3D bodies: exact queries on spheres, boxes and star-shaped meshes; bad input errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.geometry.mesh3d import MeshError, box_mesh
from uvnav.obstacles.bodies3d import MeshBody, SphereBody, StarBody

coord = st.floats(-4.0, 4.0, allow_nan=False)
point = st.tuples(coord, coord, coord).map(np.array)
STAR = StarBody(1.0, np.array([[1, 0, 0], [0, 0, 1], [0, 1, 0]]), np.array([0.5, -0.3, 0.4]),
                np.array([4.0, 4.0, 6.0]))  # fmt: skip
STAR_MESH = STAR.to_mesh(2)


@settings(max_examples=150, deadline=None)
@given(p=point)
def test_sphere_body_is_exact(p: np.ndarray) -> None:
    b = SphereBody(1.3)
    q, d = b.nearest_body(p)
    assert d == pytest.approx(np.linalg.norm(p) - 1.3, abs=1e-12)
    assert np.linalg.norm(q) == pytest.approx(1.3)
    t = b.ray_body(p[None], -p[None] / max(np.linalg.norm(p), 1e-9))
    if np.linalg.norm(p) > 1.3:
        assert t[0] == pytest.approx(np.linalg.norm(p) - 1.3, abs=1e-9)


@settings(max_examples=150, deadline=None)
@given(p=point)
def test_star_mesh_sign_agrees_with_winding_and_distance_with_brute_force(p: np.ndarray) -> None:
    _, d = STAR_MESH.nearest_body(p)
    inside = bool(STAR_MESH.contains_body(p[None])[0])
    assert (d < 0) == inside or abs(d) < 1e-9
    # brute force over every triangle
    from uvnav.geometry.mesh3d import closest_points_on_triangles

    _, d2 = closest_points_on_triangles(p, STAR_MESH.tri)
    assert abs(d) == pytest.approx(np.sqrt(d2.min()), abs=1e-12)


def test_star_body_is_non_convex_and_its_mesh_is_close_to_the_analytic_surface() -> None:
    assert STAR.tessellation_error(2) < 0.08
    # non-convex: the midpoint of two surface points on either side of the dent is outside
    top = STAR_MESH.vertices[np.argmax(STAR_MESH.vertices[:, 2] + STAR_MESH.vertices[:, 0])]
    assert STAR.contains_body(np.array([[0.0, 0.0, 0.5]]))[0]
    assert not STAR.contains_body(np.array([[0.0, 0.0, 0.9]]))[0]  # the dent at +z
    assert top is not None
    with pytest.raises(ValueError, match="dents too deep"):
        StarBody(1.0, np.array([[1.0, 0, 0]]), np.array([-1.2]), np.array([3.0]))


def test_mesh_body_is_recentred_on_its_volume_centroid_and_rejects_bad_meshes() -> None:
    v, f = box_mesh([1.0, 0.5, 0.25])
    b = MeshBody.from_mesh(v + 7.0, f)
    assert np.allclose(b.vertices.mean(axis=0), 0.0, atol=1e-12)
    assert b.volume == pytest.approx(1.0)
    assert b.bounding_radius == pytest.approx(np.linalg.norm([1.0, 0.5, 0.25]))
    with pytest.raises(MeshError, match="degenerate"):
        MeshBody.from_mesh(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0.0]]),
                           np.array([[0, 1, 2], [0, 1, 3], [1, 2, 3], [0, 2, 3]]))  # fmt: skip
    t = b.ray_body(np.array([[-5.0, 0, 0]]), np.array([[1.0, 0, 0]]))
    assert t[0] == pytest.approx(4.0)
