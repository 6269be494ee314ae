"""An experiment added by a third party: one file (``dummy_experiment/dummy_experiment.py``),
installed through the ``uvnav.experiments`` entry-point group only — no uvnav module edited —
is listed by ``uvnav reproduce --list``, runs with ``uvnav reproduce dummy`` into the results
store, and its section is in the written report (and in ``uvnav report``'s).

The plug-in is installed as a package manager would: a ``.dist-info`` folder with its
``entry_points.txt`` on the path of fresh processes.
"""

from __future__ import annotations

import os
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from uvnav.bench.store import ResultsStore
from uvnav.experiments.sections import SECTIONS_DIR, ChapterSection, save_section

PLUGIN = Path(__file__).with_name("dummy_experiment")


def _install(site: Path, entry_points: str) -> dict[str, str]:
    """The environment of a process with the plug-in of ``entry_points`` installed."""
    info = site / "dummy_experiment-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: dummy-experiment\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(entry_points)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(site), str(PLUGIN), env.get("PYTHONPATH", "")])
    return env


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    return _install(
        tmp_path_factory.mktemp("site"), "[uvnav.experiments]\ndummy = dummy_experiment:DUMMY\n"
    )


def _uvnav(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "uvnav.cli", *args],
        env={**env, "COLUMNS": "200"},
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_list_shows_the_plugin_experiment(installed: dict[str, str]) -> None:
    out = _uvnav(installed, "reproduce", "--list")
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    (line,) = [x for x in lines if x.startswith("dummy ")]
    assert line.split()[1] == "yes" and "straight-v1 on open-field (test)" in line
    names = [x.split()[0] for x in lines[1:] if not x.startswith(" ")]  # not the sizes
    assert names[-3:] == ["ch7", "dummy", "beyond"] and "ch2" in names
    assert max(len(x) for x in lines) <= 80


def test_reproduce_dummy_runs_it_and_reports_its_section(
    installed: dict[str, str], tmp_path: Path
) -> None:
    res, rep = tmp_path / "res", tmp_path / "rep"
    earlier = ChapterSection("ch7", "Chapter 7 — earlier", "run before", rows=[{"quantity": "q7"}])
    save_section(earlier, res / SECTIONS_DIR)
    args = ("--seeds", "2", "--start-seed", "3", "--workers", "1")
    out = _uvnav(
        installed, "reproduce", "dummy", *args, "--results", str(res), "--report", str(rep)
    )
    assert out.returncode == 0, out.stderr
    assert "2 of 2 (dummy-measured)" in out.stdout  # its rows, printed
    assert f"wrote {rep / 'index.html'}" in out.stdout
    html = (rep / "index.html").read_text(encoding="utf-8")
    assert 'id="section-dummy"' in html and "2 of 2 (dummy-measured)" in html
    assert html.index('id="section-ch7"') < html.index('id="section-dummy"')  # report order
    assert (res / SECTIONS_DIR / "dummy.json").is_file()
    with sqlite3.connect(res / "uvnav.sqlite") as db:
        seeds = db.execute(
            "select e.seed from episodes e join campaigns c on c.id = e.campaign_id "
            "where c.name = 'dummy-open-field' order by e.seed"
        ).fetchall()
    assert seeds == [(3,), (4,)]
    # ``uvnav report`` of that database keeps the plug-in's saved section
    site = tmp_path / "site"
    again = _uvnav(installed, "report", str(res / "uvnav.sqlite"), "--out", str(site))
    assert again.returncode == 0, again.stderr
    assert 'id="section-dummy"' in (site / "index.html").read_text(encoding="utf-8")


def test_a_plugin_taking_a_builtin_name_is_refused_in_one_line(tmp_path: Path) -> None:
    env = _install(tmp_path / "site", "[uvnav.experiments]\nch2 = dummy_experiment:SHADOW\n")
    db = tmp_path / "uvnav.sqlite"
    ResultsStore(db).close()
    for args in (
        ("reproduce", "--list"),
        ("reproduce", "ch3", "--seeds", "1"),
        ("report", str(db)),
    ):
        out = _uvnav(env, *args)
        assert out.returncode == 2, out.stdout
        (line,) = out.stderr.strip().splitlines()
        assert line.startswith("error: experiment 'ch2' of dummy_experiment:SHADOW")
        assert "already registered" in line
