"""The report's summary shows the social metrics (:mod:`uvnav.sim.social`) where they exist."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from uvnav.bench.store import ResultsStore
from uvnav.viz.report import summary_table

SOCIAL = (
    "min_separation [m]", "too_close_frequency", "intrusion_time [s]", "intrusion_ratio",
    "personal_space_time [s]", "min_time_to_collision [s]",
)  # fmt: skip


def _metrics(**social: Any) -> dict[str, Any]:
    return {
        "success": True, "collision": False, "min_clearance": 0.1, "path_length": 5.0,
        "detour_ratio": 1.1, "time_ratio": 1.2, "control_effort": 0.0, "limit_violations": 0,
        "mode_switches": 0, "decision_us_median": 1.0, "decision_us_p99": 2.0, **social,
    }  # fmt: skip


def test_summary_lists_social_metrics_of_crowd_campaigns(tmp_path: Path) -> None:
    with ResultsStore(tmp_path / "r.sqlite") as store:
        crowd, plain = store.campaign("crowd"), store.campaign("plain")
        for seed, sep in enumerate((0.1, 0.3)):
            store.add_episode(
                crowd, scenario="c", family="crowd", controller="law", seed=seed,
                status="success", metrics=_metrics(
                    min_separation=sep, too_close_frequency=0.5, intrusion_time=1.0,
                    intrusion_ratio=0.25, path_irregularity=0.2, personal_space_time=0.75,
                    min_time_to_collision=1.5 + seed, heading_irregularity=0.1, jerk=3.0,
                ),
            )  # fmt: skip
        store.add_episode(
            plain, scenario="p", controller="law", seed=0, status="success",
            metrics=_metrics(path_irregularity=0.4, heading_irregularity=0.2, jerk=1.0),
        )  # fmt: skip
        (row,) = summary_table(store.episodes_frame("crowd"))
        (other,) = summary_table(store.episodes_frame("plain"))
    assert row["min_separation [m]"].endswith("/ 0.200")  # mean [CI] / median of 0.1, 0.3
    assert row["too_close_frequency"] == "0.500 [0.500, 0.500] / 0.500"
    assert row["intrusion_time [s]"].startswith("1.00")
    assert row["intrusion_ratio"] == "0.250 [0.250, 0.250] / 0.250"
    assert row["path_irregularity [rad/m]"].startswith("0.200")
    assert row["personal_space_time [s]"] == "0.75 [0.75, 0.75] / 0.75"
    assert row["min_time_to_collision [s]"].endswith("/ 2.00")  # of 1.5 and 2.5
    assert row["heading_irregularity [rad]"] == "0.100 [0.100, 0.100] / 0.100"
    assert row["jerk [m/s³]"] == "3.00 [3.00, 3.00] / 3.00"
    assert list(row).index("jerk [m/s³]") < list(row).index("decision_us_median [µs]")
    assert other["jerk [m/s³]"] == "1.00 / 1.00" and "heading_irregularity [rad]" in other
    assert not set(SOCIAL) & set(other)  # no pedestrian: no pedestrian columns
    assert other["path_irregularity [rad/m]"] == "0.400 / 0.400"
