"""Absent bodies (a replayed pedestrian outside its recorded interval): no query sees them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvnav.obstacles import (
    ConstantVelocity,
    DiscBody,
    FieldTemplate,
    Obstacle,
    ObstacleBatch,
    ObstacleField,
    ObstacleState,
    PolygonBody,
)
from uvnav.scenarios.pedestrians import PedestrianReplay
from uvnav.sensors.exact import lidar_scan, sense_obstacles

SQUARE = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])


def field(present: list[bool] | None) -> ObstacleField:
    tpl = FieldTemplate.from_bodies([DiscBody(0.5), PolygonBody(SQUARE), DiscBody(0.3)])
    centres = np.array([[1.0, 0.0], [0.0, 2.0], [6.0, 0.0]])
    pres = None if present is None else np.array(present)
    return tpl.field(centres, np.zeros(3), np.zeros((3, 2)), np.zeros(3), pres)


def test_all_present_is_the_plain_field() -> None:
    f = field([True, True, True])
    assert f.present is None
    np.testing.assert_array_equal(f.nearest(np.zeros(2))[0], field(None).nearest(np.zeros(2))[0])


@pytest.mark.parametrize("nearest", [True, False])
def test_query_skips_absent_bodies(nearest: bool) -> None:
    f = field([False, True, True])
    q = f.query((0.0, 0.0), 10.0, nearest=nearest)
    assert q.ids.tolist() == [1, 2]
    assert q.distance[0] == pytest.approx(1.5)
    assert q.bounds[0] > 0.5  # the absent disc at 0.5 m does not bound the nearest distance
    dist, near, inside = f.nearest(np.array([1.0, 0.0]))  # inside the absent disc
    assert math.isinf(dist[0]) and np.isnan(near[0]).all() and not inside[0]
    assert dist[1] == pytest.approx(math.hypot(0.5, 1.5))


def test_nobody_present_means_no_nearest_body() -> None:
    f = field([False, False, False])
    q = f.query((1.0, 0.0), 10.0, nearest=True)  # the point is inside absent disc 0
    assert len(q.ids) == 0 and q.bounds == (math.inf, math.inf)
    assert sense_obstacles(np.zeros(2), f, sensing_range=100.0) == ()
    assert np.isinf(f.nearest(np.zeros(2))[0]).all()


def test_sensing_and_lidar_never_see_absent_bodies() -> None:
    f = field([False, True, True])
    ids = [r.obstacle_id for r in sense_obstacles(np.zeros(2), f, sensing_range=10.0)]
    assert ids == [1, 2]
    hits = f.ray_hits(np.zeros(2), np.array([[1.0, 0.0], [0.0, 1.0]]), max_range=10.0)
    assert math.isinf(hits[0, 0]) and hits[0, 2] == pytest.approx(5.7)
    assert hits[1, 1] == pytest.approx(1.5)
    scan = lidar_scan(np.zeros(3), f, n_rays=4, max_range=10.0)
    assert scan.ranges[2] == pytest.approx(5.7)  # beam 0 rad passes through the absent disc


def test_batch_reports_presence_from_the_models() -> None:
    ped = PedestrianReplay(np.array([0.5, 1.5]), np.array([[0.0, 1.0], [1.0, 1.0]]))
    walker = Obstacle(DiscBody(0.3), ped.initial_state(0.0), ped, "ped")
    still = Obstacle.moving_disc((3.0, 0.0), 0.5)
    batch = ObstacleBatch([walker, still])
    assert batch.present is not None and batch.present.tolist() == [False, True]
    seen = []
    t = 0.0
    for _ in range(20):
        batch.step(t, 0.1)
        t += 0.1
        fld = batch.field()
        seen.append(fld.present is None)
        q = fld.query((0.0, 1.0), 0.0, nearest=True)
        assert (0 in q.ids.tolist()) == ped.present(t)
    assert seen == [ped.present(0.1 * (i + 1)) for i in range(20)]
    # a batch without absent-capable models has no presence at all
    plain = ObstacleBatch(
        [Obstacle(DiscBody(0.1), ObstacleState(np.zeros(2)), ConstantVelocity(np.zeros(2)))]
    )
    assert plain.present is None


def test_from_obstacles_at_a_time_marks_absent_bodies() -> None:
    ped = PedestrianReplay(np.array([1.0, 2.0]), np.array([[0.0, 0.0], [1.0, 0.0]]))
    ob = Obstacle(DiscBody(0.3), ped.initial_state(0.0), ped, "ped")
    assert ObstacleField.from_obstacles([ob], t=0.0).present is not None
    assert ObstacleField.from_obstacles([ob], t=1.5).present is None
    assert ObstacleField.from_obstacles([ob]).present is None
