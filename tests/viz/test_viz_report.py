"""HTML report: renders, self-contained, tables and figures present and linked relatively."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from uvnav.bench.campaign import Job, run_campaign
from uvnav.bench.store import ResultsStore
from uvnav.viz.report import SIMULATION_NOTE, summary_table, write_report

SCENES = Path(__file__).parents[1] / "scenes"


def small_scene(seed: int) -> str:
    """Even seeds: a disc blocks the straight path."""
    return str(SCENES / ("tiny-blocked.yaml" if seed % 2 == 0 else "tiny-clear.yaml"))


@pytest.fixture
def db(tmp_path: Path) -> Path:
    path = tmp_path / "results" / "uvnav.sqlite"
    jobs = [
        Job(
            controller="straight-v1",
            seed=s,
            scenario=small_scene(s),
            label="small",
            family="small-family",
            params=p,
        )
        for s in range(4)
        for p in ({}, {"slow_radius": 0.5})
    ]
    # no such scene file: an error whose message holds markup
    jobs.append(Job(controller="straight-v1", seed=7, scenario="bad <scene>.yaml", label="broken"))
    with ResultsStore(path) as store:
        run_campaign(store, "demo", jobs, config={"purpose": "test"})
    return path


def test_report_renders_tables_and_figures(db: Path, tmp_path: Path) -> None:
    fig_dir = tmp_path / "elsewhere"
    fig_dir.mkdir()
    fig = fig_dir / "extra.png"
    fig.write_bytes(b"\x89PNG\r\n\x1a\n" + b"0" * 100)
    table = [
        {
            "quantity": "Fig. 2.10 path length, zhang2019-v1",
            "thesis": "14.9 m",
            "measured": "15.02 m",
            "note": "<script>alert(1)</script>",
        },
        {"quantity": "straight line", "thesis": "14.14 m", "measured": "14.14 m", "note": ""},
    ]
    out = tmp_path / "report"
    index = write_report(db, out, figures=[fig, (fig, "the same, captioned")], table=table)
    assert index == out / "index.html" and index.is_file()
    html = index.read_text(encoding="utf-8")
    assert "Thesis reported vs uvnav measured" in html
    assert "Fig. 2.10 path length, zhang2019-v1" in html and "15.02 m" in html
    assert "<script>" not in html and "&lt;script&gt;" in html  # escaped
    assert SIMULATION_NOTE.split(":")[0] in html
    # the summary table: family and controller, success rate of 2 of 4 per parameter set
    assert "small-family" in html and "straight-v1" in html and "50.0%" in html
    # errors are listed with their message
    assert "bad &lt;scene&gt;" in html
    # every image exists next to index.html and is linked relatively
    srcs = re.findall(r'<img src="([^"]+)"', html)
    assert len(srcs) == 3  # two given (same file twice) + the campaign summary
    for src in srcs:
        assert "/" not in src and (out / src).is_file()
    assert "the same, captioned" in html
    # self-contained: no external resources
    assert not re.search(r"(src|href)=\"(https?:)?//", html)
    assert "http://" not in html and "https://" not in html


def test_report_without_table_or_figures(db: Path, tmp_path: Path) -> None:
    index = write_report(db, tmp_path / "r", summary_figure=False)
    html = index.read_text(encoding="utf-8")
    assert "No reproduction table" in html
    assert "<img" not in html


def test_report_of_empty_database(tmp_path: Path) -> None:
    path = tmp_path / "empty.sqlite"
    ResultsStore(path).close()
    html = write_report(path, tmp_path / "r").read_text(encoding="utf-8")
    assert "holds no episodes" in html


def test_missing_inputs_raise(db: Path, tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        write_report(tmp_path / "nope.sqlite", tmp_path / "r")
    with pytest.raises(FileNotFoundError):
        write_report(db, tmp_path / "r", figures=[tmp_path / "missing.png"])


def test_summary_table_values(db: Path) -> None:
    with ResultsStore(db) as store:
        rows = summary_table(store.episodes_frame())
    by_family = {r["family"]: r for r in rows}
    assert by_family["small-family"]["episodes"] == 8
    # 4 of 8, with the 95 % Wilson interval [21.5 %, 78.5 %], flagged as a small sample
    assert by_family["small-family"]["success rate"] == "50.0% [21.5%, 78.5%] ⚠ n=8"
    assert by_family["small-family"]["collision rate"] == "50.0% [21.5%, 78.5%] ⚠ n=8"
    assert by_family["broken"]["errors"] == 1
    assert by_family["broken"]["min_clearance [m]"] == "–"


def test_wilson_interval_matches_the_closed_form() -> None:
    from uvnav.viz.report import wilson_interval

    lo, hi = wilson_interval(0, 10)
    assert lo == 0.0 and abs(hi - 0.2775) < 1e-4  # the rule-of-three-like upper bound at 0/10
    lo, hi = wilson_interval(198, 200)
    assert lo < 0.99 < hi and hi <= 1.0


def test_one_summary_table_per_campaign(tmp_path: Path) -> None:
    """Two campaigns over the same scene and law get separate tables with their own numbers."""
    from uvnav.bench.campaign import Job, run_campaign

    db = tmp_path / "two.sqlite"
    with ResultsStore(db) as store:
        run_campaign(store, "first", [Job(controller="straight-v1", seed=0, generator_seed=0)])
        run_campaign(
            store,
            "second",
            [Job(controller="straight-v1", seed=s, generator_seed=s) for s in range(3)],
        )
        df = store.episodes_frame()
    from uvnav.viz.report import campaign_summaries

    tables = {t["campaign"]: t for t in campaign_summaries(df)}
    assert set(tables) == {"first", "second"}
    assert [r["episodes"] for r in tables["first"]["rows"]] == [1]
    assert [r["episodes"] for r in tables["second"]["rows"]] == [3]
    html = write_report(db, tmp_path / "r", summary_figure=False, animations=0).read_text()
    assert "Campaign <code>first</code>" in html and "Campaign <code>second</code>" in html
    assert html.count('class="summary-table"') == 2


def test_benchmark_section_reads_the_json_files(tmp_path: Path) -> None:
    import json

    bench = tmp_path / "bench"
    bench.mkdir()
    machine = {"timestamp": "t", "cpu_count": 2, "load_average_1m": 0.5, "python": "3.11"}
    (bench / "summary.json").write_text(
        json.dumps(
            {
                "machine": machine,
                "targets": {
                    "x": {
                        "what": "steps/s",
                        "limit": 10.0,
                        "direction": ">=",
                        "measured": 12345.6,
                        "pass": True,
                    },
                },
            }
        )
    )
    (bench / "peers.json").write_text(
        json.dumps(
            {
                "machine": machine,
                "results": {
                    "100": {
                        "irsim": {"steps_per_s": 31.0},
                        "uvnav": {"steps_per_s": 2234.0},
                        "ratio_uvnav_over_irsim": 72.06,
                    },
                },
            }
        )
    )
    # navground not installed: its script records only that, and the report skips the file
    (bench / "peers_navground.json").write_text(json.dumps({"available": False}))
    from uvnav.viz.report import benchmark_tables

    tables = benchmark_tables(bench)
    assert [t["title"] for t in tables] == [
        "Targets (make bench)",
        "World stepping: uvnav vs ir-sim",
    ]
    assert tables[0]["rows"][0]["measured"] == "12,345.6"
    assert tables[1]["rows"][0]["uvnav / ir-sim"] == "72.1×"
    db = tmp_path / "e.sqlite"
    ResultsStore(db).close()
    html = write_report(db, tmp_path / "r", bench_dir=bench).read_text(encoding="utf-8")
    assert "uvnav vs ir-sim" in html and "2,234.0" in html
    (bench / "peers.json").write_text(json.dumps({"machine": machine}))
    with pytest.raises(ValueError, match="expected field 'results'"):
        benchmark_tables(bench)
