"""Chapter 2 reproduction: the table is read from the store; end-to-end run, resume, staleness."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from uvnav.bench.store import ResultsStore, StaleCampaignError
from uvnav.experiments import ch2 as rp

SCENES = ["thesis-ch2-fig2-10-comparison", "thesis-ch2-one-obstacle"]
LAWS = ["zhang2019-v1", "savkin-wang2013-v1"]


def fake_metrics(path_length: float, *, success: bool = True, clearance: float = 0.25) -> dict:
    return {
        "success": success,
        "collision": not success,
        "min_clearance": clearance,
        "path_length": path_length,
        "detour_ratio": path_length / 14.142 if success else None,
        "time_to_goal": 22.0 if success else None,
        "time_ratio": 1.1 if success else None,
        "control_effort": 1.0,
        "limit_violations": 0,
        "mode_switches": 2,
        "decision_us_median": 10.0,
        "decision_us_p99": 20.0,
    }


def test_build_table_reads_measured_values_from_the_store(tmp_path: Path) -> None:
    with ResultsStore(tmp_path / "r.sqlite") as store:
        scenes = store.campaign(rp.SCENES_CAMPAIGN)
        lengths = {"zhang2019-v1": 15.02, "savkin-wang2013-v1": 16.31}
        for law in LAWS:
            store.add_episode(
                scenes,
                scenario=SCENES[0],
                controller=law,
                seed=0,
                status="success",
                metrics=fake_metrics(lengths[law]),
            )
        store.add_episode(
            scenes,
            scenario=SCENES[1],
            controller="zhang2019-v1",
            seed=0,
            status="collision",
            metrics=fake_metrics(7.5, success=False, clearance=-0.01),
        )
        store.add_episode(
            scenes,
            scenario=SCENES[1],
            controller="savkin-wang2013-v1",
            seed=0,
            status="error",
            error="ValueError: discs only",
        )
        rand = store.campaign(rp.RANDOM_CAMPAIGN)
        outcomes = {0: "success", 1: "timeout", 2: "success", 3: "collision"}
        for law in LAWS:
            for seed, status in outcomes.items():
                ok = status == "success"
                store.add_episode(
                    rand,
                    scenario=f"random-ch2/{seed:04d}",
                    family="random-ch2",
                    controller=law,
                    seed=seed,
                    status=status,
                    metrics=fake_metrics(15.0, success=ok),
                )
        rows, failures = rp.build_table(store, SCENES, LAWS, straight_line=14.1421356)
    table = {r["quantity"]: r for r in rows}
    assert all(set(r) == {"quantity", "thesis", "measured", "note"} for r in rows)
    z = table["Fig. 2.10 path length, zhang2019-v1"]
    assert (z["thesis"], z["measured"]) == ("14.9 m", "15.02 m")
    assert "+0.8% vs thesis" in z["note"]
    s = table["Fig. 2.10 path length, savkin-wang2013-v1"]
    assert (s["thesis"], s["measured"]) == ("15.7 m", "16.31 m")
    assert table["Fig. 2.10 straight-line distance I–T"]["measured"] == "14.14 m"
    assert table["Fig. 2.10 straight-line distance I–T"]["thesis"] == "14.14 m"
    ratio = table["Fig. 2.10 path length ratio savkin-wang2013-v1 / zhang2019-v1"]
    assert ratio["measured"] == f"{16.31 / 15.02:.3f}"
    assert (
        table[f"outcome, {rp.scene_label(SCENES[0])}, zhang2019-v1"]["measured"]
        == "success, no collision"
    )
    assert table[f"outcome, {rp.scene_label(SCENES[1])}, zhang2019-v1"]["measured"] == "collision"
    assert table[f"outcome, {rp.scene_label(SCENES[1])}, zhang2019-v1"]["thesis"].startswith(
        "success, no collision"
    )
    assert (
        table[f"outcome, {rp.scene_label(SCENES[1])}, savkin-wang2013-v1"]["measured"]
        == "error: ValueError: discs only"
    )
    assert (
        table[f"min clearance, {rp.scene_label(SCENES[1])}, zhang2019-v1"]["measured"] == "-0.010 m"
    )
    assert (
        table[f"min clearance, {rp.scene_label(SCENES[0])}, savkin-wang2013-v1"]["measured"]
        == "0.250 m"
    )
    for law in LAWS:
        assert table[f"random campaign success rate, {law}"]["measured"] == "50.0% (2/4)"
        assert (
            table[f"random campaign failed seeds, {law}"]["measured"]
            == "1 (timeout), 3 (collision)"
        )
    assert failures == [
        (law, seed, st) for law in LAWS for seed, st in ((1, "timeout"), (3, "collision"))
    ]


def test_table_when_nothing_was_run(tmp_path: Path) -> None:
    with ResultsStore(tmp_path / "r.sqlite") as store:
        rows, failures = rp.build_table(store, [], LAWS, straight_line=None)
    table = {r["quantity"]: r for r in rows}
    assert table["Fig. 2.10 path length, zhang2019-v1"]["measured"] == "not run"
    assert table["random campaign success rate, zhang2019-v1"]["measured"] == "not run"
    assert failures == []


def test_code_fingerprint_covers_simulation_code_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import uvnav

    fake = tmp_path / "uvnav"
    (fake / "sim").mkdir(parents=True)
    (fake / "viz").mkdir()
    (fake / "__init__.py").write_text("")
    (fake / "sim" / "loop.py").write_text("x = 1\n")
    (fake / "viz" / "plot.py").write_text("y = 1\n")
    monkeypatch.setattr(uvnav, "__file__", str(fake / "__init__.py"))
    first = rp.code_fingerprint()
    assert len(first) == 16 and rp.code_fingerprint() == first
    (fake / "viz" / "plot.py").write_text("y = 2\n")
    assert rp.code_fingerprint() == first
    (fake / "sim" / "loop.py").write_text("x = 2\n")
    assert rp.code_fingerprint() != first


TWIN = "straight-twin-test-v1"


def test_reproduce_end_to_end_resume_and_staleness(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scenarios = pytest.importorskip("uvnav.scenarios")
    from uvnav.controllers import base
    from uvnav.controllers.straight import StraightController, StraightParams

    # a second "law" (straight-v1 under another name) so the comparison figure is drawn without
    # depending on the Ch. 2 controllers; in-process only (workers=1), removed after the test
    twin = base.ControllerInfo(TWIN, StraightController, StraightParams, "test twin")
    base.available_controllers()
    monkeypatch.setitem(base._REGISTRY, TWIN, twin)
    thesis = [n for n in scenarios.list_builtin() if n.startswith(rp.THESIS_PREFIX)]
    assert rp.COMPARISON_SCENE in thesis
    laws = ("straight-v1", TWIN)
    kw: dict[str, Any] = dict(
        n_random=3,
        controllers=laws,
        workers=1,
        progress=False,
        baselines=("apf-v1",),
        n_baseline_seeds=2,
        n_crowd_seeds=1,
    )
    # pin the fingerprint: concurrent edits of the tree must not look like stale results
    monkeypatch.setattr(rp, "code_fingerprint", lambda: "a" * 16)
    from uvnav.viz.reproduction import render_reproduction

    report_dir = tmp_path / "report"
    summary = rp.reproduce(tmp_path / "results", report_dir, render=render_reproduction, **kw)
    assert summary.db_path == tmp_path / "results" / "uvnav.sqlite" and summary.db_path.is_file()
    assert summary.report_path == tmp_path / "report" / "index.html"
    html = summary.report_path.read_text(encoding="utf-8")
    assert "Thesis reported vs uvnav measured" in html
    for fig in summary.figures:
        assert fig.is_file() and fig.parent == tmp_path / "report" / "ch2"
        assert f'src="ch2/{fig.name}"' in html
    # test-sized run: only the Chapter 2 section, with its rows and every figure
    assert [s.key for s in summary.sections] == ["ch2"]
    assert not (tmp_path / "results" / "ch6-quick").exists()  # no CNN training in tests
    ch2 = summary.sections[0]
    assert [f.path for f in ch2.figures] == summary.figures
    assert ch2.rows and {r["quantity"] for r in ch2.rows} <= {r["quantity"] for r in summary.table}
    assert 'id="section-ch2"' in html and "seeds 0–2" in ch2.intro
    names = [f.name for f in summary.figures]
    # one per scene and law, the Fig. 2.10 comparison, the random-campaign summary
    assert len(names) == 2 * len(thesis) + 2
    assert f"{rp.COMPARISON_SCENE}--comparison.png" in names
    assert names[-1] == f"{rp.RANDOM_CAMPAIGN}-summary.png"
    assert summary.campaigns[rp.SCENES_CAMPAIGN]["ran"] == 2 * len(thesis)
    assert summary.campaigns[rp.RANDOM_CAMPAIGN]["ran"] == 6
    with ResultsStore(summary.db_path) as store:
        df = store.episodes_frame(rp.RANDOM_CAMPAIGN)
    expected = sorted(
        (str(c), int(s), str(st))
        for c, s, st in zip(df["controller"], df["seed"], df["status"], strict=True)
        if st != "success"
    )
    assert sorted(summary.failures) == expected
    rows = {r["quantity"]: r["measured"] for r in summary.table}
    for law in laws:
        n_ok = int(((df["status"] == "success") & (df["controller"] == law)).sum())
        assert rows[f"random campaign success rate, {law}"] == f"{n_ok / 3:.1%} ({n_ok}/3)"
    # the same law under two names gives the same Fig. 2.10 path length
    assert rows["Fig. 2.10 path length, straight-v1"] == rows[f"Fig. 2.10 path length, {TWIN}"]

    # unchanged code: everything is resumed, nothing runs again
    again = rp.reproduce(tmp_path / "results", tmp_path / "report", render=None, **kw)
    assert again.campaigns[rp.SCENES_CAMPAIGN]["ran"] == 0
    assert again.campaigns[rp.RANDOM_CAMPAIGN]["skipped"] == 6
    assert again.table == summary.table and again.report_path is None

    # changed code: the run refuses, names the campaigns to remove, and deletes nothing
    monkeypatch.setattr(rp, "code_fingerprint", lambda: "b" * 16)
    with ResultsStore(summary.db_path) as store:
        before = {c["name"]: store.count(c["name"]) for c in store.campaigns()}
    with pytest.raises(StaleCampaignError) as err:
        rp.reproduce(tmp_path / "results", tmp_path / "report", render=None, **kw)
    message = str(err.value)
    assert "\n" not in message and "uvnav forget" in message
    assert set(err.value.campaigns) == set(before)  # every stale campaign at once
    with ResultsStore(summary.db_path) as store:
        assert {c["name"]: store.count(c["name"]) for c in store.campaigns()} == before
    # removed (uvnav forget), they run again
    with ResultsStore(summary.db_path) as store:
        for name in before:
            store.delete_campaign(name)
    rerun = rp.reproduce(tmp_path / "results", tmp_path / "report", render=None, **kw)
    c = rerun.campaigns[rp.RANDOM_CAMPAIGN]
    assert (c["ran"], c["skipped"]) == (6, 0)


def test_baseline_and_crowd_rows_come_from_the_store(tmp_path: Path) -> None:
    """The beyond-the-thesis rows count the stored baseline and crowd episodes."""
    summary = rp.reproduce(
        tmp_path / "results",
        tmp_path / "report",
        render=None,
        n_random=1,
        controllers=("straight-v1",),
        baselines=("apf-v1",),
        n_baseline_seeds=2,
        n_crowd_seeds=1,
        workers=1,
        progress=False,
    )
    rows = {r["quantity"]: r for r in summary.table}
    assert rows["success rate, random-ch2, apf-v1"]["measured"].endswith("/2)")
    crowd = [q for q in rows if q.startswith("success rate, crowd-")]
    assert {q.split(", ")[1].split("[")[0] for q in crowd} == {"crowd-eth", "crowd-hotel"}
    assert all(rows[q]["measured"].endswith("/1)") for q in crowd)
    assert "do not react" in rows[crowd[0]]["note"]
