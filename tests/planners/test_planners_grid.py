"""Occupancy grid rasterisation against shapely distances."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.planners import empty_grid, occupancy_grid, safe_inflation


@settings(max_examples=15, deadline=None)
@given(
    st.floats(1.0, 4.0),
    st.floats(1.0, 4.0),
    st.floats(0.2, 1.5),
    st.floats(0.0, 0.6),
    st.floats(0.05, 0.3),
)
def test_occupied_iff_centre_within_inflation(cx, cy, half, inflate, res) -> None:
    square = np.array(
        [
            [cx - half, cy - half],
            [cx + half, cy - half],
            [cx + half, cy + half],
            [cx - half, cy + half],
        ]
    )
    grid = occupancy_grid((0, 0, 6, 6), res, [square], inflate=inflate)
    gx, gy = grid.cell_centres()
    d = shapely.distance(shapely.Polygon(square), shapely.points(gx, gy))
    # round-joined buffer approximates the disc by 16 segments per quarter: 0.2 % slack
    tol = 2e-3 * inflate + 1e-9
    assert not grid.occupied[d > inflate + tol].any()
    assert grid.occupied[d < inflate - tol].all()


def test_cells_and_world() -> None:
    grid = empty_grid((-1.0, 2.0, 3.0, 4.0), 0.5)
    assert grid.shape == (4, 8)
    assert grid.to_cell((-0.9, 2.1)) == (0, 0)
    assert grid.to_cell((100, 100)) == (3, 7)
    np.testing.assert_allclose(grid.to_world([(1, 2)]), [[0.25, 2.75]])
    assert grid.inside((2.9, 3.9)) and not grid.inside((3.1, 3.0))
    assert safe_inflation(0.3, 0.1) == pytest.approx(0.3 + 0.1 / np.sqrt(2))
    with pytest.raises(ValueError, match="resolution"):
        empty_grid((0, 0, 1, 1), 0.0)
    with pytest.raises(ValueError, match="bounds"):
        empty_grid((0, 0, 0, 1), 0.1)


def test_disc_obstacle() -> None:
    grid = occupancy_grid((0, 0, 4, 4), 0.1, discs=[(2.0, 2.0, 0.5)], inflate=0.25)
    assert grid.occupied[grid.to_cell((2.05, 2.65))]
    assert not grid.occupied[grid.to_cell((2.05, 2.85))]
