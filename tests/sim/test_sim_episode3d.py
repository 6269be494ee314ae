"""The 3D step loop: straight flight, exact collision detection, the thesis-ch3 scenes."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.controllers.base import make_law
from uvnav.dynamics.vehicle3d import Vehicle3DCommand, Vehicle3DSpec
from uvnav.geometry.mesh3d import box_mesh
from uvnav.obstacles.bodies3d import MeshBody, SphereBody
from uvnav.obstacles.motion3d import ConstantMotion3D, Obstacle3D, ObstacleState3D
from uvnav.scenarios import load_scenario
from uvnav.sim.episode3d import Episode3DSetup, Sensing3DConfig
from uvnav.sim.metrics import METRIC_NAMES
from uvnav.sim.run import run_episode


class _Straight:
    """Flies along its initial heading at V_max (ignores obstacles)."""

    name = "straight-test"
    oracle = False
    mode = "M1"

    def reset(self, spec, goal, rng) -> None:  # type: ignore[no-untyped-def]
        self.v = spec.v_max

    def act(self, obs) -> Vehicle3DCommand:  # type: ignore[no-untyped-def]
        return Vehicle3DCommand(self.v, np.zeros(3))


def _setup(obstacles: list[Obstacle3D]) -> Episode3DSetup:
    return Episode3DSetup(
        spec=Vehicle3DSpec(1.0, 1.0, 0.1), start=np.zeros(3), heading=np.array([1.0, 0, 0]),
        goal=np.array([10.0, 0, 0]), obstacles=obstacles, t_max=20.0,
        sensing=Sensing3DConfig(velocities="known"),
    )  # fmt: skip


def test_free_flight_reaches_the_goal_straight() -> None:
    res = run_episode(_setup([]), _Straight(), np.random.default_rng(0))
    tr = res.trajectory
    m = res.metrics
    assert res.status == "success" and set(m.to_dict()) == set(METRIC_NAMES)
    assert m.detour_ratio == pytest.approx(1.0, abs=1e-6)
    assert m.time_to_goal == pytest.approx(9.7, abs=0.06)
    assert tr is not None and np.allclose(tr.position[:, 1:], 0.0)


@pytest.mark.parametrize("record", [True, False])
def test_collision_with_a_mesh_is_detected_at_the_first_overlapping_step(record: bool) -> None:
    box = MeshBody.from_mesh(*box_mesh([0.5, 0.5, 0.5]))
    ob = Obstacle3D(box, ConstantMotion3D(np.zeros(3)), ObstacleState3D(np.array([5.0, 0.2, 0])))
    res = run_episode(_setup([ob]), _Straight(), np.random.default_rng(0), record=record)
    assert res.status == "collision"
    # the robot's sphere (r = 0.1) first overlaps the face x = 4.5 when its centre passes 4.4
    assert -0.05 <= res.metrics.min_clearance < 0
    assert res.metrics.path_length == pytest.approx(4.45, abs=0.051)


def test_unrecorded_and_recorded_runs_give_identical_metrics() -> None:
    def run(record: bool) -> dict:
        ob = Obstacle3D(SphereBody(1.0), ConstantMotion3D(np.array([0.0, 0.2, 0.0])),
                        ObstacleState3D(np.array([5.0, -1.5, 0.3])))  # fmt: skip
        c = make_law("zhang2020-3d-v1", vehicle="vehicle3d", oracle=True)
        res = run_episode(_setup([ob]), c, np.random.default_rng(1), record=record)
        d = res.metrics.to_dict()
        d.pop("decision_us_median"), d.pop("decision_us_p99")
        return d

    assert run(True) == run(False)


@pytest.mark.parametrize(
    ("scene", "velocities"),
    [
        ("thesis-ch3-fig3-5-single-cycle", "known"),
        ("thesis-ch3-fig3-6-whole-manoeuvre", "estimated"),
        ("thesis-ch3-several-obstacles", "estimated"),
    ],
)
def test_zhang2020_3d_reaches_e_without_collision_on_the_thesis_scenes(
    scene: str, velocities: str
) -> None:
    sc = load_scenario(scene)
    setup = sc.build(0, velocities=velocities)
    c = make_law("zhang2020-3d-v1", vehicle="vehicle3d", oracle=velocities == "known")
    res = run_episode(setup, c, np.random.default_rng(0), record=False)
    assert res.status == "success"
    assert res.metrics.min_clearance > 0.1
    assert res.metrics.limit_violations == 0


def test_compiled_kernels_and_numpy_fallback_give_the_same_episode(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The whole episode (sensing, zhang2020-3d decisions, exact clearance every step) with the
    numba kernels and with the numpy fallback: same status and metrics to 1e-9."""
    from uvnav.geometry.kernels3d import numba_available, use_compiled

    if not numba_available():
        pytest.skip("numba (the 'fast' extra) absent")
    from uvnav.scenarios.generators3d import random_ch3_scenario

    out = []
    for flag in (True, False):
        monkeypatch.setattr("uvnav.geometry.kernels3d._ENABLED", flag)
        assert use_compiled(flag) is flag
        sc = random_ch3_scenario(3)
        setup = sc.build(3, velocities="known")
        setup.t_max = 15.0
        c = make_law("zhang2020-3d-v1", vehicle="vehicle3d", oracle=True)
        res = run_episode(setup, c, np.random.default_rng(3), record=False)
        out.append(res)
    a, b = out
    assert a.status == b.status
    for key in ("min_clearance", "path_length", "control_effort"):
        assert getattr(a.metrics, key) == pytest.approx(getattr(b.metrics, key), abs=1e-9)
