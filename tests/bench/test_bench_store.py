"""Results store (DESIGN §5): schema, round trips, NULL handling, the resume key."""

from __future__ import annotations

import math
import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import pytest

from uvnav.bench.store import ResultsStore, params_hash, trajectory_from_bytes, trajectory_to_bytes
from uvnav.controllers import make_controller
from uvnav.dynamics import UnicycleSpec
from uvnav.obstacles import DiscBody, Obstacle, ObstacleState, PolygonBody, RandomTurn
from uvnav.sim import METRIC_NAMES, EpisodeResult, EpisodeSetup, run_episode
from uvnav.sim.metrics import SOCIAL_METRIC_NAMES


def tiny_setup(seed: int) -> EpisodeSetup:
    """Robot (0, 0) -> (3, 0); a polygon wanders off the path, a disc blocks it if seed % 3 == 0."""
    rng = np.random.default_rng(seed)
    square = PolygonBody.from_vertices(
        np.array([[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]])
    )
    obstacles = [
        Obstacle(
            square, ObstacleState(np.array([1.5, 1.5])), RandomTurn((0.1, 0.2), (-0.3, 0.3), rng)
        )
    ]
    if seed % 3 == 0:
        from uvnav.obstacles import ConstantVelocity

        obstacles.append(
            Obstacle(
                DiscBody(0.3), ObstacleState(np.array([1.5, 0.0])), ConstantVelocity(np.zeros(2))
            )
        )
    return EpisodeSetup(
        spec=UnicycleSpec(1.0, 1.0, 0.1),
        start=np.array([0.0, 0.0, 0.0]),
        goal=np.array([3.0, 0.0]),
        obstacles=obstacles,
        t_max=10.0,
    )


def run_tiny(seed: int, record: bool = True) -> EpisodeResult:
    return run_episode(
        tiny_setup(seed), make_controller("straight-v1"), np.random.default_rng(seed), record=record
    )


@pytest.fixture
def store(tmp_path: Path) -> Iterator[ResultsStore]:
    with ResultsStore(tmp_path / "r.sqlite") as s:
        yield s


def test_schema_has_every_metric_column_and_wal(store: ResultsStore) -> None:
    conn = sqlite3.connect(store.path)
    cols = {row[1] for row in conn.execute("PRAGMA table_info(episodes)")}
    assert set(METRIC_NAMES) <= cols
    assert {
        "campaign_id",
        "scenario",
        "controller",
        "params_hash",
        "params",
        "seed",
        "status",
        "wall_time",
    } <= cols
    assert {row[1] for row in conn.execute("PRAGMA table_info(trajectories)")} == {
        "episode_id",
        "data",
    }
    assert conn.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    conn.close()


def test_campaign_is_get_or_create(store: ResultsStore) -> None:
    a = store.campaign("c1", {"n": 1})
    assert store.campaign("c1", {"n": 2}) == a
    assert store.campaign("c2") != a
    assert [c["config"] for c in store.campaigns()] == [{"n": 1}, {}]


def test_params_hash_ignores_key_order() -> None:
    assert params_hash({"a": 1, "b": 2.5}) == params_hash({"b": 2.5, "a": 1})
    assert params_hash({"a": 1}) != params_hash({"a": 2})
    assert params_hash(None) == params_hash({})


def test_episode_and_trajectory_round_trip(store: ResultsStore) -> None:
    result = run_tiny(1)
    assert result.trajectory is not None
    cid = store.campaign("c")
    eid = store.add_episode(
        cid,
        scenario="tiny",
        controller="straight-v1",
        seed=1,
        status=result.status,
        params={"slow_radius": 0.0},
        metrics=result.metrics,
        wall_time=0.01,
        trajectory=result.trajectory,
    )
    back = store.episode_result(eid)
    assert back.status == result.status
    assert back.metrics == result.metrics
    traj, orig = back.trajectory, result.trajectory
    assert traj is not None
    for name in (
        "times",
        "robot",
        "commands",
        "clearance",
        "nearest_id",
        "obstacle_centres",
        "obstacle_headings",
        "obstacle_velocities",
        "obstacle_omegas",
    ):
        np.testing.assert_array_equal(getattr(traj, name), getattr(orig, name))
    assert traj.modes == orig.modes
    assert len(traj.obstacle_shapes) == len(orig.obstacle_shapes) == 1
    np.testing.assert_array_equal(traj.obstacle_outline(0, 5), orig.obstacle_outline(0, 5))
    # the blob is a plain npz: no pickles inside
    assert trajectory_from_bytes(trajectory_to_bytes(orig)).modes == orig.modes
    assert store.load_trajectory(eid) is not None


def test_unrecorded_episode_has_no_trajectory(store: ResultsStore) -> None:
    result = run_tiny(2, record=False)
    eid = store.add_episode(
        store.campaign("c"),
        scenario="tiny",
        controller="straight-v1",
        seed=2,
        status=result.status,
        metrics=result.metrics,
    )
    assert store.load_trajectory(eid) is None


def test_failed_episode_metrics_are_sql_null(store: ResultsStore) -> None:
    cid = store.campaign("c")
    store.add_episode(
        cid,
        scenario="tiny",
        controller="x",
        seed=0,
        status="error",
        error="RuntimeError: boom",
        metrics=None,
    )
    collided = run_tiny(0, record=False)  # seed % 3 == 0: a disc sits on the path
    assert collided.status == "collision"
    store.add_episode(
        cid,
        scenario="tiny",
        controller="straight-v1",
        seed=0,
        status=collided.status,
        metrics=collided.metrics,
    )
    # NaN and inf never reach the database either
    nan_metrics = {
        **collided.metrics.to_dict(),
        "control_effort": math.nan,
        "min_clearance": math.inf,
    }
    store.add_episode(
        cid,
        scenario="tiny",
        controller="straight-v1",
        seed=99,
        status="timeout",
        metrics=nan_metrics,
    )
    conn = sqlite3.connect(store.path)
    err_nulls = conn.execute(
        "SELECT " + ", ".join(f"{m} IS NULL" for m in METRIC_NAMES) + ", error "
        "FROM episodes WHERE status = 'error'"
    ).fetchone()
    assert all(err_nulls[:-1]) and err_nulls[-1] == "RuntimeError: boom"
    row = conn.execute(
        "SELECT time_to_goal IS NULL, detour_ratio IS NULL, time_ratio IS NULL, success, collision "
        "FROM episodes WHERE status = 'collision'"
    ).fetchone()
    assert row == (1, 1, 1, 0, 1)
    assert conn.execute(
        "SELECT control_effort IS NULL AND min_clearance IS NULL FROM episodes WHERE seed = 99"
    ).fetchone() == (1,)
    # no NaN stored anywhere: SQLite would compare NaN != NaN
    for m in METRIC_NAMES:
        assert conn.execute(f"SELECT COUNT(*) FROM episodes WHERE {m} != {m}").fetchone() == (0,)
    conn.close()
    # pandas reads the database directly; NULL becomes a missing value
    with sqlite3.connect(store.path) as c2:
        df = pd.read_sql("SELECT * FROM episodes", c2)
    assert len(df) == 3
    assert df.loc[df["status"] == "error", "path_length"].isna().all()


def test_resume_key_is_unique_but_errors_can_be_retried(store: ResultsStore) -> None:
    cid = store.campaign("c")
    result = run_tiny(1, record=False)
    kw: dict[str, Any] = dict(
        scenario="tiny", controller="straight-v1", seed=1, params={"slow_radius": 0.0}
    )
    first = store.add_episode(cid, status="error", error="flaky", **kw)
    assert ("tiny", "straight-v1", params_hash({"slow_radius": 0.0}), 1) in store.done_keys(cid)
    assert store.done_keys(cid, include_errors=False) == set()
    retried = store.add_episode(cid, status=result.status, metrics=result.metrics, **kw)
    assert retried == first
    assert store.count(cid) == 1
    assert store.episode_row(first)["status"] == result.status
    with pytest.raises(sqlite3.IntegrityError):
        store.add_episode(cid, status=result.status, metrics=result.metrics, **kw)
    # same key in another campaign is a different episode
    store.add_episode(store.campaign("other"), status=result.status, metrics=result.metrics, **kw)
    assert store.count() == 2


def test_episodes_frame_filters_by_campaign(store: ResultsStore) -> None:
    a, b = store.campaign("a"), store.campaign("b")
    for cid, seed in ((a, 1), (a, 2), (b, 1)):
        r = run_tiny(seed, record=False)
        store.add_episode(
            cid,
            scenario="tiny",
            controller="straight-v1",
            seed=seed,
            status=r.status,
            metrics=r.metrics,
            family="tiny-family",
        )
    assert len(store.episodes_frame()) == 3
    fa = store.episodes_frame("a")
    assert list(fa["seed"]) == [1, 2] and set(fa["campaign"]) == {"a"}
    assert len(store.episodes_frame(b)) == 1
    assert store.episodes_frame("missing").empty
    assert str(fa["success"].dtype) == "boolean"
    assert set(fa["family"]) == {"tiny-family"}


def test_delete_campaign(store: ResultsStore) -> None:
    cid = store.campaign("a")
    r = run_tiny(1)
    eid = store.add_episode(
        cid,
        scenario="tiny",
        controller="straight-v1",
        seed=1,
        status=r.status,
        metrics=r.metrics,
        trajectory=r.trajectory,
    )
    assert store.delete_campaign("a")
    assert store.count() == 0 and store.load_trajectory(eid) is None
    assert not store.delete_campaign("a")


def test_unknown_metric_is_rejected(store: ResultsStore) -> None:
    with pytest.raises(ValueError, match="unknown metric"):
        store.add_episode(
            store.campaign("c"),
            scenario="s",
            controller="c",
            seed=0,
            status="success",
            metrics={"speed_of_light": 3e8},
        )


def _crowd_collision() -> EpisodeResult:
    """A pedestrian walks into a standing robot: every social metric has a value."""
    from uvnav.dynamics import UnicycleCommand

    class Stand:
        name: ClassVar[str] = "stand"
        oracle = False

        @property
        def mode(self) -> str:
            return ""

        def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
            pass

        def act(self, obs: Any) -> UnicycleCommand:
            return UnicycleCommand(0.0, 0.0)

    setup = EpisodeSetup(
        spec=UnicycleSpec(1.0, 1.0, 0.2),
        start=np.array([0.0, 0.0, 0.0]),
        goal=np.array([5.0, 5.0]),
        obstacles=[Obstacle.moving_disc((-2.0, 0.1), 0.3, (1.0, 0.0))],
        dt=0.25,
        control_period=0.25,
        t_max=10.0,
    )
    return run_episode(setup, Stand(), np.random.default_rng(0), record=False)


def test_social_metrics_round_trip(store: ResultsStore) -> None:
    result = _crowd_collision()
    m = result.metrics
    assert m.collision_by == "pedestrian" and m.min_separation is not None
    assert m.too_close_time is not None and m.too_close_time > 0
    eid = store.add_episode(
        store.campaign("c"), scenario="crowd", controller="stand", seed=0, status=result.status,
        metrics=m,
    )  # fmt: skip
    assert store.episode_result(eid).metrics == m
    conn = sqlite3.connect(store.path)
    types = {row[1]: row[2] for row in conn.execute("PRAGMA table_info(episodes)")}
    conn.close()
    assert types["collision_by"] == "TEXT" and types["min_separation"] == "REAL"
    row = store.episodes_frame("c").iloc[0]
    assert row["collision_by"] == "pedestrian"
    assert row["intrusion_time"] == m.intrusion_time


SOCIAL = SOCIAL_METRIC_NAMES


def test_database_without_social_columns_reads_and_upgrades(tmp_path: Path) -> None:
    db = tmp_path / "old.sqlite"
    with ResultsStore(db) as store:
        old = run_tiny(1, record=False)
        eid = store.add_episode(
            store.campaign("c"), scenario="tiny", controller="straight-v1", seed=1,
            status=old.status, metrics=old.metrics,
        )  # fmt: skip
    with sqlite3.connect(db) as conn:  # an older database: no social columns
        for name in SOCIAL:
            conn.execute(f"ALTER TABLE episodes DROP COLUMN {name}")
    with ResultsStore(db, readonly=True) as store:  # read as it is, not migrated
        df = store.episodes_frame("c")
        assert all(df[name].isna().all() for name in SOCIAL)
        back = store.episode_result(eid).metrics
        assert all(getattr(back, name) is None for name in SOCIAL)
        assert back.min_clearance == old.metrics.min_clearance
    with sqlite3.connect(db) as conn:
        assert not set(SOCIAL) & {row[1] for row in conn.execute("PRAGMA table_info(episodes)")}
    with ResultsStore(db) as store:  # opened for writing: the columns are added
        new = _crowd_collision()
        nid = store.add_episode(
            store.campaign("c"), scenario="crowd", controller="stand", seed=0,
            status=new.status, metrics=new.metrics,
        )  # fmt: skip
        assert store.episode_result(nid).metrics == new.metrics
        assert store.episode_result(eid).metrics.collision_by is None
