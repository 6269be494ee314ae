"""Stage 2 orders (thesis Ch. 7 §7.3.2): TSP (OR-Tools), spiral, clusters, merged tour."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvnav.recon import tour as T  # noqa: N812
from uvnav.recon.lattice import optimal_lattice
from uvnav.recon.terrain import square_area


def lattice_points(side: float = 300.0, R: float = 30.0) -> np.ndarray:
    sol = optimal_lattice(square_area(side), R, n_lambda=6, refine=0)
    return np.column_stack([sol.xy, np.zeros(sol.n)])


def test_tsp_is_a_tour_from_start_and_near_lattice_bound() -> None:
    p = lattice_points()
    o = T.tsp_order(p, start=5)
    assert o[0] == 5
    assert sorted(o.tolist()) == list(range(len(p)))
    # every closed tour has n edges no shorter than the lattice spacing sqrt(3)·R
    lower = len(p) * math.sqrt(3) * 30.0
    length = T.tour_length(p, o)
    assert lower - 1e-6 <= length <= 1.10 * lower


def test_tsp_is_reproducible() -> None:
    p = lattice_points(200.0, 25.0)
    rng = np.random.default_rng(0)
    p[:, 2] = rng.uniform(40, 60, len(p))
    np.testing.assert_array_equal(T.tsp_order(p), T.tsp_order(p))


def test_spiral_is_a_tour_and_layers_go_inwards() -> None:
    p = lattice_points()
    o = T.spiral_order(p, start=0)
    assert o[0] == 0
    assert sorted(o.tolist()) == list(range(len(p)))
    # outside in: distance to the centroid decreases along the order (in trend)
    r = np.linalg.norm(p[o, :2] - p[:, :2].mean(axis=0), axis=1)
    q = len(r) // 4
    assert r[:q].mean() > r[-q:].mean()


def test_kmeans_clusters_and_cluster_tours() -> None:
    p = lattice_points(200.0, 30.0)
    lab = T.kmeans_clusters(p[:, :2], 2, seed=0)
    assert set(lab.tolist()) == {0, 1}
    np.testing.assert_array_equal(lab, T.kmeans_clusters(p[:, :2], 2, seed=0))
    tours = T.cluster_tours(p, lab)
    assert sorted(np.concatenate(tours).tolist()) == list(range(len(p)))
    for c, tour in enumerate(tours):
        assert np.all(lab[tour] == c)
    with pytest.raises(ValueError, match=r"^uavs"):
        T.kmeans_clusters(p[:, :2], 0)
    with pytest.raises(ValueError, match=r"^tour method"):
        T.cluster_tours(p, lab, method="zigzag")


def test_merge_keeps_first_tour_order_and_visits_all() -> None:
    p = lattice_points()
    lab = T.kmeans_clusters(p[:, :2], 2, seed=0)
    a, b = T.cluster_tours(p, lab)
    m = T.merge_tours(p, a, b)
    assert m[0] == a[0]
    assert sorted(m.tolist()) == list(range(len(p)))
    kept = [i for i in m.tolist() if i in set(a.tolist())]
    assert kept == a.tolist()
    # the merge costs at most the two separate tours plus twice the gap between the clusters
    gap = np.linalg.norm(p[a][:, None, :] - p[b][None, :, :], axis=2).min()
    assert (
        T.tour_length(p, m)
        <= T.tour_length(p, a) + T.tour_length(p, b) + 2 * gap + 2 * math.sqrt(3) * 30
    )
