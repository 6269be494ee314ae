"""episode_metrics: the DESIGN §4 metrics assembled once for every simulator."""

from __future__ import annotations


def test_episode_metrics_ratios_exist_only_where_they_mean_something() -> None:
    from uvnav.sim.metrics import episode_metrics

    kw = dict(
        path_length=15.0,
        shortest=12.0,
        straight_time=20.0,
        min_clearance=0.3,
        control_effort=1.5,
        limit_violations=0,
        mode_switches=2,
        decision_us=[10.0, 20.0, 30.0],
    )
    ok = episode_metrics(status="success", reached_at=25.0, **kw)  # type: ignore[arg-type]
    assert ok.success and not ok.collision
    assert ok.detour_ratio == 15.0 / 12.0 and ok.time_ratio == 25.0 / 20.0
    assert ok.decision_us_median == 20.0 and 29.0 < ok.decision_us_p99 <= 30.0
    hit = episode_metrics(status="collision", reached_at=None, **kw)  # type: ignore[arg-type]
    assert hit.collision and not hit.success
    assert hit.detour_ratio is None and hit.time_ratio is None and hit.time_to_goal is None
    none = episode_metrics(
        status="timeout", reached_at=None, **{**kw, "min_clearance": None, "decision_us": []}
    )  # type: ignore[arg-type]
    assert none.min_clearance is None and none.decision_us_median == 0.0
