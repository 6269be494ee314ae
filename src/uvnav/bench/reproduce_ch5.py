"""Thesis Chapter 5 reproduction: the BPNN experiment (50 and 150 samples) and closed-loop runs.

Reference: Y. Zhang and J. Zhang, ICCAE 2022; thesis Chapter 5 §5.4 (Figs. 5.5-5.8): a BPNN
trained on 50, then 150 "groups of data", randomly divided into training, validation and test
groups; reported test errors (target - output) of [-1.688, 1.861] (distance) and [-2.806, 4.454]
(sensor number) with 50 samples, [-0.04884, 0.3578] and [-0.08559, 0.1147] with 150.

:func:`reproduce_ch5` measures, for every sample count and seed: the network's error range on its
own random test group (what the thesis reports) and on an independent test set of
``n_test`` samples (a fairer estimate with so few samples), beside the min/argmin-of-readings
baseline on the same samples; and runs ``zhang2022-uuv3d-v1`` on the three thesis scenes and on
``random-ch5:<seed>`` scenes with the geometric (baseline), network and oracle locators, with and
without sonar noise.  Everything is written to ``results_dir/ch5.json`` and the table rows
"thesis reported vs uvnav measured" are built from those measurements only.  Figures are drawn by
a renderer the caller injects (``bench`` may not import ``viz``, DESIGN §1).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.controllers.zhang_uuv3d import (
    GeometricLocator,
    Locator,
    ModelLocator,
    OracleLocator,
    ZhangUUV3D,
    ZhangUUV3DParams,
)
from uvnav.learning.bpnn import (
    THESIS_ERROR_RANGES,
    BPNNConfig,
    TrainedBPNN,
    error_table,
    load_checkpoint,
    save_checkpoint,
    train_bpnn,
)
from uvnav.scenarios.ch5 import (
    build_uuv3d,
    list_ch5_builtin,
    load_ch5_scenario,
    random_ch5_scenario,
)
from uvnav.sensors.sonar_dataset import SonarDataset, sample_sonar_dataset
from uvnav.sim.episode_uuv3d import UUV3DResult, run_uuv3d_episode

QUICK_SIZES: tuple[int, ...] = (50, 150)
FULL_SIZES: tuple[int, ...] = (50, 150, 500, 5000)
QUICK_SEEDS, FULL_SEEDS = 2, 5
QUICK_RANDOM, FULL_RANDOM = 3, 300
QUICK_NOISES: tuple[float, ...] = (0.0,)
LOCATORS: tuple[str, ...] = ("geometric", "network", "oracle")
#: sonar range noise [m] of the noisy closed-loop runs
NOISE_STD = 0.05
#: samples of the network used in closed loop
CLOSED_LOOP_SAMPLES = 500
#: tessellation level of the sampled obstacles (320 triangles: readings and targets are computed
#: on the same mesh, so the data are consistent; the mesh is within a few cm of the analytic body)
DATA_SUBDIVISIONS = 2


def make_locator(
    name: str, model_path: Path | None = None, model: TrainedBPNN | None = None
) -> Locator:
    """``geometric``, ``network`` (a trained model or a checkpoint path) or ``oracle``.

    Raises:
        ValueError: unknown name, or ``network`` without a model.
        CheckpointError: the checkpoint cannot be read.
    """
    if name == "geometric":
        return GeometricLocator()
    if name == "oracle":
        return OracleLocator()
    if name == "network":
        if model is None and model_path is None:
            raise ValueError("locator 'network' needs a model (--model CHECKPOINT)")
        return ModelLocator(model if model is not None else load_checkpoint(model_path))  # type: ignore[arg-type]
    raise ValueError(f"unknown locator {name!r}; known: geometric, network, oracle")


@dataclass
class Ch5Summary:
    """What :func:`reproduce_ch5` measured.

    Attributes:
        learning: one row per (samples, seed): error summaries on the split's test group and on
            the independent test set, network and baseline, training time [s], epochs.
        closed_loop: one row per episode: scene, locator, noise, seed, status, metrics.
        table: rows ``{quantity, thesis, measured, note}``.
        json_path: where everything was written.
        figures: figure files written by the renderer.
        wall_time: seconds.
    """

    learning: list[dict[str, Any]] = field(default_factory=list)
    closed_loop: list[dict[str, Any]] = field(default_factory=list)
    table: list[dict[str, Any]] = field(default_factory=list)
    json_path: Path | None = None
    figures: list[Path] = field(default_factory=list)
    wall_time: float = 0.0
    models: dict[str, Any] = field(default_factory=dict, repr=False)
    datasets: dict[str, Any] = field(default_factory=dict, repr=False)


def learning_row(
    n: int, seed: int, test: SonarDataset, config: BPNNConfig | None = None
) -> tuple[dict[str, Any], TrainedBPNN, SonarDataset]:
    """Train on ``n`` fresh samples (seed ``seed``) and measure errors (module docstring)."""
    rng = np.random.default_rng(10_000 + seed)
    ds = sample_sonar_dataset(n, rng, subdivisions=DATA_SUBDIVISIONS)
    cfg = config or BPNNConfig()
    tic = time.perf_counter()
    model = train_bpnn(ds.inputs, ds.targets(), rng, cfg, offset=ds.baseline())
    train_s = time.perf_counter() - tic
    grp = model.split["test"]
    own = error_table(
        model.predict(ds.inputs[grp], ds.baseline()[grp]), ds.targets()[grp], ds.baseline()[grp]
    )
    ind = error_table(model.predict(test.inputs, test.baseline()), test.targets(), test.baseline())
    row = {
        "samples": n,
        "seed": seed,
        "variant": "residual" if cfg.residual else "plain",
        "train_seconds": round(train_s, 3),
        "epochs": len(model.history["train"]),
        "best_epoch": model.best_epoch,
        "stop_reason": model.stop_reason,
        "test_group": own,
        "independent": ind,
    }
    return row, model, ds


def _episode_row(
    scene: str, locator: str, noise: float, seed: int, res: UUV3DResult
) -> dict[str, Any]:
    return {
        "scene": scene,
        "locator": locator,
        "noise_std": noise,
        "seed": seed,
        "status": res.status,
        "entered_inner_space": res.entered_inner_space,
        **res.metrics.to_dict(),
    }


def run_closed_loop(
    scenes: Sequence[str],
    locators: dict[str, Locator],
    *,
    noises: Sequence[float] = (0.0,),
    seed: int = 0,
    on_episode: Callable[[], None] | None = None,
    record: bool = False,
) -> tuple[list[dict[str, Any]], dict[tuple[str, str, float], UUV3DResult]]:
    """Every scene x locator x noise once with ``seed``; rows and (when ``record``) results."""
    rows: list[dict[str, Any]] = []
    kept: dict[tuple[str, str, float], UUV3DResult] = {}
    for scene in scenes:
        scn = load_ch5_scenario(scene)
        for noise in noises:
            setup = build_uuv3d(scn, noise_std=noise)
            for name, loc in locators.items():
                params = ZhangUUV3DParams(**scn.controller.params)  # type: ignore[arg-type]
                res = run_uuv3d_episode(
                    setup, ZhangUUV3D(params, loc), np.random.default_rng(seed), record=record
                )
                rows.append(_episode_row(scene, name, noise, seed, res))
                if record:
                    kept[(scene, name, noise)] = res
                if on_episode is not None:
                    on_episode()
    return rows, kept


def _range(lo: float, hi: float) -> str:
    return f"[{lo:.4g}, {hi:.4g}]"


def build_ch5_table(summary: Ch5Summary) -> list[dict[str, Any]]:
    """Rows "thesis reported vs uvnav measured" from the measured rows only."""
    rows: list[dict[str, Any]] = []
    by_n: dict[tuple[str, int], list[dict[str, Any]]] = {}
    for r in summary.learning:
        by_n.setdefault((str(r["variant"]), int(r["samples"])), []).append(r)
    for (variant, n), rs in sorted(by_n.items()):
        ref = THESIS_ERROR_RANGES.get(n)
        for out in ("distance", "index"):
            g = [r["test_group"]["network"][out] for r in rs]
            ind = [r["independent"]["network"][out] for r in rs]
            base = [r["independent"]["baseline"][out] for r in rs]
            rows.append(
                {
                    "quantity": f"Ch5 BPNN ({variant}) {n} samples: {out} error, test group",
                    "thesis": _range(*ref[out]) if ref else "-",
                    "measured": _range(min(x["lo"] for x in g), max(x["hi"] for x in g)),
                    "note": f"union over {len(rs)} seeds; median MAE "
                    f"{np.median([x['mae'] for x in g]):.3g}",
                }
            )
            rows.append(
                {
                    "quantity": f"Ch5 BPNN ({variant}) {n}: {out} MAE, indep. test (baseline)",
                    "thesis": "-",
                    "measured": f"{np.median([x['mae'] for x in ind]):.3g} "
                    f"({np.median([x['mae'] for x in base]):.3g})",
                    "note": f"{rs[0]['independent']['network'][out]['n']} samples; median of "
                    f"{len(rs)} seeds; baseline = min/argmin of readings",
                }
            )
    cl = summary.closed_loop
    for group in sorted({(r["locator"], r["noise_std"]) for r in cl}):
        loc, noise = group
        thesis_rows = [
            r
            for r in cl
            if (r["locator"], r["noise_std"]) == group and str(r["scene"]).startswith("thesis-ch5")
        ]
        rand_rows = [
            r
            for r in cl
            if (r["locator"], r["noise_std"]) == group and str(r["scene"]).startswith("random-ch5")
        ]
        if thesis_rows:
            ok = sum(bool(r["success"]) for r in thesis_rows)
            inner = sum(bool(r["entered_inner_space"]) for r in thesis_rows)
            rows.append(
                {
                    "quantity": f"Ch5 thesis scenes reached, no collision ({loc}, noise {noise} m)",
                    "thesis": "3/3",
                    "measured": f"{ok}/{len(thesis_rows)}",
                    "note": f"entered Scene 2 inner space: {inner}",
                }
            )
        if rand_rows:
            ok = sum(bool(r["success"]) for r in rand_rows)
            fails = [f"{r['scene']}:{r['status']}" for r in rand_rows if not r["success"]]
            rows.append(
                {
                    "quantity": f"Ch5 random scenes success ({loc}, noise {noise} m)",
                    "thesis": "-",
                    "measured": f"{ok / len(rand_rows):.1%} of {len(rand_rows)}",
                    "note": ("failures: " + ", ".join(fails[:6])) if fails else "no failure",
                }
            )
    return rows


def reproduce_ch5(
    results_dir: Path,
    *,
    full: bool = False,
    sizes: Sequence[int] | None = None,
    n_seeds: int | None = None,
    n_random: int | None = None,
    n_test: int = 500,
    scenes: Sequence[str] | None = None,
    noises: Sequence[float] | None = None,
    closed_loop_samples: int = CLOSED_LOOP_SAMPLES,
    progress: bool = True,
    render: Callable[[Ch5Summary, Path], list[Path]] | None = None,
    report_dir: Path | None = None,
) -> Ch5Summary:
    """Run the Chapter 5 reproduction (module docstring) and write ``results_dir/ch5.json``.

    Args:
        results_dir: folder of ``ch5.json`` and the closed-loop network's checkpoint.
        full: thesis-size runs (sizes up to 5000, 5 seeds, 300 random scenes).
        sizes: sample counts (default 50, 150, 500 quick).
        n_seeds: seeds per sample count (default 3 quick).
        n_random: random closed-loop scenes per locator and noise level (default 10 quick).
        n_test: size of the independent test set.
        scenes: thesis scenes to run (default all three).
        noises: sonar noise levels [m] of the closed-loop runs (default 0 quick, 0 and 0.05 full).
        closed_loop_samples: training samples of the closed-loop (residual) network.
        progress: rich progress bar on stderr.
        render: figure renderer ``(summary, report_dir) -> files`` (e.g.
            :func:`uvnav.viz.figures_ch5.render_ch5`); ``None`` skips figures.
        report_dir: folder of the figures.
    """
    from rich.progress import Progress

    tic = time.perf_counter()
    results_dir = Path(results_dir)
    results_dir.mkdir(parents=True, exist_ok=True)
    sizes = tuple(sizes) if sizes is not None else (FULL_SIZES if full else QUICK_SIZES)
    seeds = n_seeds if n_seeds is not None else (FULL_SEEDS if full else QUICK_SEEDS)
    n_rand = n_random if n_random is not None else (FULL_RANDOM if full else QUICK_RANDOM)
    summary = Ch5Summary()
    test = sample_sonar_dataset(
        n_test, np.random.default_rng(999_999), subdivisions=DATA_SUBDIVISIONS
    )
    summary.datasets["independent_test"] = test
    scene_list = list(scenes) if scenes is not None else list_ch5_builtin()
    default_noises = (0.0, NOISE_STD) if full else QUICK_NOISES
    noise_list = tuple(noises) if noises is not None else default_noises
    n_episodes = (len(scene_list) + n_rand) * len(LOCATORS) * len(noise_list)
    variants = (BPNNConfig(), BPNNConfig(residual=True))
    with Progress(disable=not progress, transient=True) as prog:
        task = prog.add_task("Ch5 BPNN", total=len(sizes) * seeds * len(variants) + 1)
        for n in sizes:
            for s in range(seeds):
                for cfg in variants:
                    row, model, ds = learning_row(n, s, test, cfg)
                    summary.learning.append(row)
                    if s == 0:
                        key = f"n{n}" + ("r" if cfg.residual else "")
                        summary.models[key] = model
                        summary.datasets[key] = ds
                    prog.advance(task)
        # the closed-loop network: a residual one trained once on CLOSED_LOOP_SAMPLES samples
        cl_row, cl_model, _ = learning_row(closed_loop_samples, 100, test, variants[1])
        summary.learning.append(cl_row)
        save_checkpoint(cl_model, results_dir / "ch5_bpnn")
        summary.models["closed_loop"] = cl_model
        prog.advance(task)
        locators: dict[str, Locator] = {
            "geometric": GeometricLocator(),
            "network": ModelLocator(cl_model),
            "oracle": OracleLocator(),
        }
        task2 = prog.add_task("Ch5 closed loop", total=n_episodes)
        rows, kept = run_closed_loop(
            scene_list,
            locators,
            noises=noise_list,
            record=True,
            on_episode=lambda: prog.advance(task2),
        )
        summary.closed_loop.extend(rows)
        summary.models["episodes"] = kept
        for g in range(n_rand):
            scn_name = f"random-ch5:{g}"
            r2, _ = run_closed_loop(
                [scn_name],
                locators,
                noises=noise_list,
                seed=g,
                on_episode=lambda: prog.advance(task2),
            )
            summary.closed_loop.extend(r2)
    summary.table = build_ch5_table(summary)
    summary.wall_time = time.perf_counter() - tic
    out = {
        "learning": summary.learning,
        "closed_loop": summary.closed_loop,
        "table": summary.table,
        "wall_time": round(summary.wall_time, 2),
        "config": {
            "sizes": list(sizes),
            "seeds": seeds,
            "n_random": n_rand,
            "n_test": n_test,
            "noises": list(noise_list),
            "closed_loop_samples": closed_loop_samples,
        },
    }
    summary.json_path = results_dir / "ch5.json"
    summary.json_path.write_text(json.dumps(out, indent=1, default=_json_default))
    if render is not None and report_dir is not None:
        summary.figures = list(render(summary, Path(report_dir)))
    return summary


def _json_default(x: Any) -> Any:
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    raise TypeError(type(x).__name__)


__all__ = [
    "Ch5Summary",
    "build_ch5_table",
    "learning_row",
    "make_locator",
    "random_ch5_scenario",
    "reproduce_ch5",
    "run_closed_loop",
]
