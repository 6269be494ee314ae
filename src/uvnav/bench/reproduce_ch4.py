"""Thesis Chapter 4 reproduction and the random-scene campaign (the Ch. 4 part of ``uvnav run``).

:func:`reproduce_ch4` runs

1. every built-in ``thesis-ch4-*`` scene (Figs. 4.2(b), 4.7-4.9) with the thesis's law
   ``zhang2022-uuv2d-v1`` and both baselines on the same sonar (``apf-uuv2d-v1``,
   ``zhang2019-uuv2d-v1``), seed 0, trajectories recorded for the figures;
2. a random campaign on ``random-ch4:<seed>`` (1-5 deforming obstacles) with the three laws
   (quick: 10 seeds; ``full``: 200);
3. a sensor-noise sweep on the same generator: range noise 0.05 / 0.1 m and 10 % dropout
   (quick: 4 seeds per level; ``full``: 50).

Every episode becomes one JSON line in ``results_dir/ch4/episodes.jsonl`` (the metrics of
:data:`~uvnav.sim.metrics.METRIC_NAMES` plus status, scene, law, noise, seed, whether a forbidden
region was entered); a re-run skips the lines already there (resume), unless ``fresh``.  The summary
(``summary.json``) and the table "thesis reported vs uvnav measured" are computed from those lines,
never typed in.  The thesis reports no numbers for Chapter 4 (only Figs. 4.7-4.9: the vehicle
reaches E without collision), so the table's thesis column states that.

Figures are made by a renderer injected by the caller (``render=``; the CLI passes
:func:`uvnav.viz.figures_ch4.render_ch4`), because ``bench`` (layer 6) must not import ``viz``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.controllers.zhang2022_uuv2d import make_uuv2d_controller
from uvnav.scenarios.uuv2d import list_uuv2d_builtin, load_uuv2d_scenario, random_ch4_scenario
from uvnav.sim.episode_uuv2d import Uuv2dResult, run_uuv2d_episode
from uvnav.sim.metrics import METRIC_NAMES

LAW = "zhang2022-uuv2d-v1"
BASELINES: tuple[str, ...] = ("apf-uuv2d-v1", "zhang2019-uuv2d-v1")
LAWS: tuple[str, ...] = (LAW, *BASELINES)
#: (range noise std [m], dropout probability) levels of the sweep
NOISE_LEVELS: tuple[tuple[float, float], ...] = ((0.05, 0.0), (0.1, 0.0), (0.0, 0.1))
QUICK_SEEDS, FULL_SEEDS = 10, 200
QUICK_NOISE_SEEDS, FULL_NOISE_SEEDS = 4, 50


@dataclass(frozen=True)
class Ch4Job:
    """One episode: a scene (built-in name or ``random-ch4:<seed>``), a law, a seed, noise."""

    scene: str
    law: str
    seed: int
    noise_std: float = 0.0
    dropout: float = 0.0

    @property
    def key(self) -> str:
        return f"{self.scene}|{self.law}|{self.seed}|{self.noise_std:g}|{self.dropout:g}"


def run_ch4_job(job: Ch4Job, *, record: bool = False) -> tuple[dict[str, Any], Uuv2dResult]:
    """Run one job; returns its JSON row and the full result."""
    if job.scene.startswith("random-ch4:"):
        sc = random_ch4_scenario(
            int(job.scene.split(":", 1)[1]), noise_std=job.noise_std, dropout=job.dropout
        )
    else:
        sc = load_uuv2d_scenario(job.scene)
    res = run_uuv2d_episode(
        sc.to_setup(),
        make_uuv2d_controller(job.law),
        np.random.default_rng(job.seed),
        record=record,
    )
    row: dict[str, Any] = {
        "key": job.key,
        "scene": job.scene,
        "law": job.law,
        "seed": job.seed,
        "noise_std": job.noise_std,
        "dropout": job.dropout,
        "n_obstacles": len(sc.obstacles),
        "status": res.status,
        "entered_forbidden": res.entered_forbidden,
    }
    row.update(res.metrics.to_dict())
    return row, res


def _row_only(job: Ch4Job) -> dict[str, Any]:
    return run_ch4_job(job)[0]


def read_rows(path: Path) -> list[dict[str, Any]]:
    """The episode rows stored in a JSONL file (missing file: none; a torn last line is
    ignored)."""
    rows: list[dict[str, Any]] = []
    if not path.exists():
        return rows
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return rows


def run_jobs(
    jobs: Iterable[Ch4Job],
    out: Path,
    *,
    workers: int = 1,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict[str, Any]]:
    """Run the jobs not yet in ``out`` (JSONL, appended one line per finished episode).

    Returns:
        The rows of all requested jobs (stored and new).
    """
    jobs = list(jobs)
    out.parent.mkdir(parents=True, exist_ok=True)
    done = {r["key"]: r for r in read_rows(out)}
    todo = [j for j in jobs if j.key not in done]
    total = len(todo)
    with out.open("a", encoding="utf-8") as fh:
        if workers <= 1:
            results: Iterable[dict[str, Any]] = map(_row_only, todo)
            pool = None
        else:
            pool = ProcessPoolExecutor(max_workers=workers)
            results = pool.map(_row_only, todo, chunksize=1)
        try:
            for k, row in enumerate(results, 1):
                fh.write(json.dumps(row) + "\n")
                fh.flush()
                done[row["key"]] = row
                if progress is not None:
                    progress(k, total)
        finally:
            if pool is not None:
                pool.shutdown(cancel_futures=True)
    return [done[j.key] for j in jobs if j.key in done]


def campaign_jobs(
    seeds: int, noise_seeds: int, laws: Iterable[str] = LAWS
) -> tuple[list[Ch4Job], list[Ch4Job]]:
    """Jobs of the random campaign (noise-free) and of the sensor-noise sweep."""
    laws = tuple(laws)
    clean = [Ch4Job(f"random-ch4:{s}", law, s) for law in laws for s in range(seeds)]
    noisy = [
        Ch4Job(f"random-ch4:{s}", law, s, noise, drop)
        for noise, drop in NOISE_LEVELS
        for law in laws
        for s in range(noise_seeds)
    ]
    return clean, noisy


def summarise(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per (law, noise, dropout): episodes, success / collision / timeout rates, forbidden
    entries, median path length, detour ratio, minimum clearance and decision time."""
    groups: dict[tuple[str, float, float], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault((r["law"], r["noise_std"], r["dropout"]), []).append(r)
    out = []
    for (law, noise, drop), rs in sorted(groups.items()):
        n = len(rs)

        def med(name: str, rs: list[dict[str, Any]] = rs) -> float | None:
            vals = [r[name] for r in rs if r.get(name) is not None]
            return float(np.median(vals)) if vals else None

        out.append(
            {
                "law": law,
                "noise_std": noise,
                "dropout": drop,
                "episodes": n,
                "success_rate": sum(r["status"] == "success" for r in rs) / n,
                "collision_rate": sum(r["status"] == "collision" for r in rs) / n,
                "timeout_rate": sum(r["status"] == "timeout" for r in rs) / n,
                "entered_forbidden": sum(bool(r["entered_forbidden"]) for r in rs),
                "path_length": med("path_length"),
                "detour_ratio": med("detour_ratio"),
                "min_clearance": min(
                    (r["min_clearance"] for r in rs if r["min_clearance"] is not None),
                    default=None,
                ),
                "decision_us_median": med("decision_us_median"),
                "limit_violations": sum(int(r["limit_violations"]) for r in rs),
            }
        )
    return out


def failures(rows: list[dict[str, Any]], law: str = LAW) -> list[dict[str, Any]]:
    """The episodes of ``law`` that did not succeed: seed, scene, status, obstacles, clearance."""
    keep = ("scene", "seed", "noise_std", "dropout", "n_obstacles", "status", "min_clearance")
    return [{k: r[k] for k in keep} for r in rows if r["law"] == law and r["status"] != "success"]


@dataclass
class Ch4Summary:
    """What :func:`reproduce_ch4` measured and wrote."""

    scene_rows: list[dict[str, Any]]
    campaign: list[dict[str, Any]]
    failures: list[dict[str, Any]]
    table: list[dict[str, Any]]
    figures: list[Path] = field(default_factory=list)
    rows_path: Path | None = None
    summary_path: Path | None = None


def _table(
    scene_rows: list[dict[str, Any]], campaign: list[dict[str, Any]]
) -> list[dict[str, Any]]:
    table: list[dict[str, Any]] = []
    for r in scene_rows:
        if r["law"] != LAW:
            continue
        clear = r["min_clearance"]
        table.append(
            {
                "quantity": f"Ch.4 {r['scene']}: outcome",
                "thesis": "reaches E, no collision (figure only)",
                "measured": f"{r['status']}, min clearance "
                + (f"{clear:.3f} m" if clear is not None else "-")
                + (", ENTERED inner space" if r["entered_forbidden"] else ""),
                "note": LAW,
            }
        )
    for c in campaign:
        if c["noise_std"] == 0 and c["dropout"] == 0:
            table.append(
                {
                    "quantity": f"Ch.4 random-ch4 success ({c['law']}, n={c['episodes']})",
                    "thesis": "not reported",
                    "measured": f"{100 * c['success_rate']:.1f} %",
                    "note": f"collisions {100 * c['collision_rate']:.1f} %",
                }
            )
    return table


def reproduce_ch4(
    results_dir: Path,
    report_dir: Path | None = None,
    *,
    full: bool = False,
    workers: int = 1,
    fresh: bool = False,
    render: Callable[..., list[Path]] | None = None,
    seeds: int | None = None,
    noise_seeds: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Ch4Summary:
    """Run the Chapter 4 reproduction and campaign (see the module docstring).

    Args:
        results_dir: where ``ch4/episodes.jsonl`` and ``ch4/summary.json`` go.
        report_dir: where the renderer puts figures (``report_dir/ch4``).
        full: thesis-size campaign (200 seeds, 50 per noise level) instead of the quick one.
        workers: processes for the campaign.
        fresh: discard stored episodes first.
        render: ``render(out_dir, scene_results, summary) -> [paths]`` (figures).
        seeds, noise_seeds: override the campaign sizes.
    """
    out_dir = Path(results_dir) / "ch4"
    out_dir.mkdir(parents=True, exist_ok=True)
    rows_path = out_dir / "episodes.jsonl"
    if fresh and rows_path.exists():
        rows_path.unlink()
    scene_results: dict[tuple[str, str], Uuv2dResult] = {}
    scene_rows = []
    for scene in list_uuv2d_builtin():
        for law in LAWS:
            row, res = run_ch4_job(Ch4Job(scene, law, 0), record=True)
            scene_rows.append(row)
            scene_results[(scene, law)] = res
    n = seeds if seeds is not None else (FULL_SEEDS if full else QUICK_SEEDS)
    nn = (
        noise_seeds
        if noise_seeds is not None
        else (FULL_NOISE_SEEDS if full else QUICK_NOISE_SEEDS)
    )
    clean, noisy = campaign_jobs(n, nn)
    rows = run_jobs(clean + noisy, rows_path, workers=workers, progress=progress)
    campaign = summarise(rows)
    fails = failures([r for r in rows if r["noise_std"] == 0 and r["dropout"] == 0])
    table = _table(scene_rows, campaign)
    summary_path = out_dir / "summary.json"
    summary_path.write_text(
        json.dumps(
            {"scenes": scene_rows, "campaign": campaign, "failures": fails, "table": table},
            indent=1,
            default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else str(x),
        ),
        encoding="utf-8",
    )
    summary = Ch4Summary(scene_rows, campaign, fails, table, [], rows_path, summary_path)
    if render is not None and report_dir is not None:
        summary.figures = list(render(Path(report_dir) / "ch4", scene_results, summary))
    return summary


__all__ = [
    "LAWS",
    "METRIC_NAMES",
    "Ch4Job",
    "Ch4Summary",
    "campaign_jobs",
    "failures",
    "read_rows",
    "reproduce_ch4",
    "run_ch4_job",
    "run_jobs",
    "summarise",
]
