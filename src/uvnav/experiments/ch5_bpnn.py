"""Thesis Chapter 5's BPNN experiment: the network that locates the nearest obstacle from nine
sonar readings, trained on 50, then 150 samples (and more).

Reference: Y. Zhang and J. Zhang, ICCAE 2022; thesis Chapter 5 §5.4 (Figs. 5.5-5.8): a BPNN
trained on 50, then 150 "groups of data", randomly divided into training, validation and test
groups; reported test errors (target - output) of [-1.688, 1.861] (distance) and [-2.806, 4.454]
(sensor number) with 50 samples, [-0.04884, 0.3578] and [-0.08559, 0.1147] with 150.

:func:`learning_row` measures, for one sample count and seed: the network's error range on its
own random test group (what the thesis reports) and on an independent test set (a fairer
estimate with so few samples), beside the min/argmin-of-readings baseline on the same samples.
Two kinds of targets are learnt (every row is labelled by both):

* the **literal experiment** — the thesis's set-up: the plain network (toolbox ``fitnet``
  shape) trained on min/argmin of its own nine inputs, the toolbox's random 70/15/15 division,
  at 50 and 150 samples, over many seeds (20 quick, 50 full): the median error ranges and the
  share of seeds inside the thesis's ranges;
* **true-geometry targets** (ours) — the nearest distance and sensor of the body itself — for the
  plain, residual and residual-Huber variants at every sample count.

The thesis reports its 50-sample result as a failure and its 150-sample one as a success, so the
table (:func:`learning_table`) states each comparison that way (:func:`thesis_statement`): at 50
samples a run agrees with the thesis when it fails too, and "inside the 50-sample range" is never
counted as agreement.

**Resumable.**  Every sampled data set (with the generator state after sampling, so training
continues exactly as in one go) and every learning row with its trained network is a stage of
the results folder's stage cache (:class:`uvnav.bench.stages.StageCache`), keyed by its inputs
and made by the code of the cache's fingerprint (:func:`uvnav.experiments.ch5.fingerprint`): a
row's inputs hold its settings, targets and division, its data set's :attr:`~Stage.ref` and the
digest of the independent test set, so new data retrain it.  The closed-loop runs that use the
network are :mod:`uvnav.experiments.ch5`.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.bench.stages import Stage, StageCache
from uvnav.experiments.rows import table_row
from uvnav.learning.bpnn import (
    ACCEPTED_SAMPLES,
    THESIS_ACCEPTED,
    THESIS_ERROR_RANGES,
    BPNNConfig,
    TrainedBPNN,
    error_table,
    load_checkpoint,
    save_checkpoint,
    split_sizes,
    train_bpnn,
)
from uvnav.sensors.sonar_dataset import SonarDataset, sample_sonar_dataset
from uvnav.stages import write_atomic

QUICK_SIZES: tuple[int, ...] = (50, 150)
FULL_SIZES: tuple[int, ...] = (50, 150, 500, 5000)
QUICK_SEEDS, FULL_SEEDS = 2, 5
#: seeds of the literal experiment (thesis targets, the plain network, 50 and 150 samples)
QUICK_LITERAL_SEEDS, FULL_LITERAL_SEEDS = 20, 50
#: suffix of each network variant (:attr:`BPNNConfig.variant`) in the names of models and
#: figures (``n150h`` = 150 samples, residual-huber), and its label in captions
VARIANT_KEYS = {"plain": "", "residual": "r", "residual-huber": "h", "plain-huber": "p"}
VARIANT_LABELS = {
    "plain": "plain (thesis-style)",
    "residual": "residual",
    "residual-huber": "residual (Huber loss)",
    "plain-huber": "plain (Huber loss)",
}
#: what each kind of targets is, in the table's row labels
TARGET_LABELS = {
    "geometry": "true geometry",
    "readings": "the thesis's min/argmin of the inputs",
}


def split_model_key(key: str) -> tuple[int, str] | None:
    """``"n150h"`` -> ``(150, "residual-huber")``; ``None`` for any other name."""
    digits = key[1:].rstrip("".join(VARIANT_KEYS.values()))
    suffix = key[1 + len(digits) :]
    variant = next((v for v, k in VARIANT_KEYS.items() if k == suffix), None)
    if not key.startswith("n") or not digits.isdigit() or variant is None:
        return None
    return int(digits), variant


#: tessellation level of the sampled obstacles (320 triangles: readings and targets are computed
#: on the same mesh, so the data are consistent; the mesh is within a few cm of the analytic body)
DATA_SUBDIVISIONS = 2
#: seed of the independent test set
TEST_SEED = 999_999
#: the files of a data set's and a learning row's stage, in its folder
DATA_FILE, MODEL_FILE = "data.npz", "model"


def _dataset_stage(n: int, rng_seed: int) -> tuple[str, dict[str, Any]]:
    """Stage name and inputs of a sampled data set."""
    return f"ch5-data-n{n}-r{rng_seed}", {
        "n": n,
        "rng_seed": rng_seed,
        "subdivisions": DATA_SUBDIVISIONS,
    }


def cached_dataset(
    n: int,
    rng_seed: int,
    cache: StageCache | None = None,
    on_sample: Callable[[int], None] | None = None,
) -> tuple[SonarDataset, np.random.Generator]:
    """``n`` samples drawn with ``default_rng(rng_seed)`` and that generator *after* sampling.

    With ``cache`` the data set is the stage ``ch5-data-n<n>-r<rng_seed>`` (:func:`data_stage`),
    so a resumed run trains on the same data with the same random stream as an uninterrupted one.
    """
    if cache is None:
        rng = np.random.default_rng(rng_seed)
        ds = sample_sonar_dataset(n, rng, subdivisions=DATA_SUBDIVISIONS, on_sample=on_sample)
        return ds, rng
    ds, rng, _ = data_stage(cache, n, rng_seed, on_sample)
    return ds, rng


def data_stage(
    cache: StageCache, n: int, rng_seed: int, on_sample: Callable[[int], None] | None = None
) -> tuple[SonarDataset, np.random.Generator, Stage]:
    """The data set of :func:`cached_dataset` as a stage of ``cache``: its arrays in
    ``data.npz``, its value the generator's state after sampling.  Returns the data set read
    from the stage, the generator in that state, and the stage."""
    name, inputs = _dataset_stage(n, rng_seed)

    def build(work: Path) -> Any:
        rng = np.random.default_rng(rng_seed)
        ds = sample_sonar_dataset(n, rng, subdivisions=DATA_SUBDIVISIONS, on_sample=on_sample)
        arrays: dict[str, Any] = ds.arrays()
        write_atomic(work / DATA_FILE, lambda fh: np.savez(fh, **arrays))
        return rng.bit_generator.state

    stage = cache.run(name, inputs, build)
    with np.load(stage.folder / DATA_FILE, allow_pickle=False) as z:
        ds = SonarDataset.from_arrays({k: z[k] for k in z.files})
    rng = np.random.default_rng(rng_seed)
    rng.bit_generator.state = stage.value
    return ds, rng, stage


def _dataset_digest(ds: SonarDataset) -> str:
    """First 16 hex digits of the SHA-256 of a data set's arrays."""
    h = hashlib.sha256()
    for k, a in sorted(ds.arrays().items()):
        h.update(k.encode())
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


def learning_row(
    n: int,
    seed: int,
    test: SonarDataset,
    config: BPNNConfig | None = None,
    *,
    cache: StageCache | None = None,
    on_sample: Callable[[int], None] | None = None,
    target_kind: str = "geometry",
) -> tuple[dict[str, Any], TrainedBPNN, SonarDataset]:
    """Train on ``n`` fresh samples (seed ``seed``) and measure errors (module docstring).

    ``target_kind`` is what the network learns (:meth:`SonarDataset.targets`): ``"geometry"``
    (the true nearest distance and sensor) or ``"readings"`` (min/argmin of its own inputs, the
    thesis's set-up); both kinds train on the same data set of ``(n, seed)``.

    With ``cache`` the data set (:func:`data_stage`) and the row are stages: the row is the
    stage ``ch5-row-n<n>-s<seed>-<variant>`` (``-readings`` appended for the thesis's targets),
    its value the row and its network ``model.safetensors`` in its folder, reused by a later call
    with the same settings, targets and division, the same data set stage and the same
    independent test set (resume) under the same code fingerprint.
    """
    cfg = config or BPNNConfig()
    if cache is None:
        ds, rng = cached_dataset(n, 10_000 + seed, None, on_sample)
        row, model = _train_row(n, seed, ds, rng, test, cfg, target_kind)
        return row, model, ds
    ds, rng, data = data_stage(cache, n, 10_000 + seed, on_sample)
    suffix = "" if target_kind == "geometry" else f"-{target_kind}"
    inputs: dict[str, Any] = {
        "config": asdict(cfg),
        "targets": target_kind,
        "division": list(split_sizes(n, cfg.fractions)),  # the toolbox's rounding
        "data": data.ref,
        "test": _dataset_digest(test),
    }
    trained: list[TrainedBPNN] = []

    def build(work: Path) -> Any:
        row, model = _train_row(n, seed, ds, rng, test, cfg, target_kind)
        save_checkpoint(model, work / MODEL_FILE)
        trained.append(model)
        return json.loads(json.dumps(row, default=json_default))

    stage = cache.run(f"ch5-row-n{n}-s{seed}-{cfg.variant}{suffix}", inputs, build)
    model = trained[0] if trained else load_checkpoint(stage.folder / MODEL_FILE)
    return dict(stage.value), model, ds


def _train_row(
    n: int,
    seed: int,
    ds: SonarDataset,
    rng: np.random.Generator,
    test: SonarDataset,
    cfg: BPNNConfig,
    target_kind: str,
) -> tuple[dict[str, Any], TrainedBPNN]:
    """Train on ``ds`` with ``rng`` and measure the row (:func:`learning_row`)."""
    y = ds.targets(target_kind)
    tic = time.perf_counter()
    model = train_bpnn(ds.inputs, y, rng, cfg, offset=ds.baseline(), target_kind=target_kind)
    train_s = time.perf_counter() - tic
    grp = model.split["test"]
    pred = model.predict(ds.inputs, ds.baseline())
    ind = error_table(
        model.predict(test.inputs, test.baseline()), test.targets(target_kind), test.baseline()
    )
    row = {
        "samples": n,
        "seed": seed,
        "variant": cfg.variant,
        "targets": target_kind,
        "division": [len(model.split[g]) for g in ("train", "val", "test")],
        "train_seconds": round(train_s, 3),
        "epochs": len(model.history["train"]),
        "best_epoch": model.best_epoch,
        "stop_reason": model.stop_reason,
        "test_group": error_table(pred[grp], y[grp], ds.baseline()[grp]),
        "all_samples": error_table(pred, y, ds.baseline()),
        "independent": ind,
    }
    if target_kind == "geometry":  # min/argmin of the inputs has no ties to report
        row["test_group_beam_ties"] = beam_ties(ds, grp, pred[grp])
    return row, model


def beam_ties(ds: SonarDataset, group: np.ndarray, predicted: np.ndarray) -> dict[str, Any]:
    """The samples of ``group`` whose true sensor is not the one with the least reading.

    There the nearest point lies between two beams whose readings differ by millimetres (the
    measured cases), so which beam "holds" it is not in the readings; an index error of up to 8
    (S1 vs S9: the index is a label, not a position) can come from one such sample.  Returns
    their count, the largest reading gap between the true sensor and argmin [m], and the
    network's index error range on the other samples (``[nan, nan]`` when none).
    """
    g = np.asarray(group, dtype=int)
    true_i = ds.target_index[g]
    tie = true_i != ds.baseline_index[g]
    gaps = ds.ranges[g[tie], true_i[tie] - 1] - ds.baseline_distance[g[tie]]
    err = true_i[~tie] - np.asarray(predicted)[~tie, 1]
    others = [float(err.min()), float(err.max())] if err.size else [math.nan, math.nan]
    return {
        "n": int(tie.sum()),
        "max_reading_gap": float(gaps.max()) if gaps.size else 0.0,
        "index_error_others": others,
    }


# ---------------------------------------------------------------------------------------- table
def _range(lo: float, hi: float) -> str:
    return f"[{lo:.4g}, {hi:.4g}]"


OUTPUTS: tuple[str, ...] = ("distance", "index")


def range_inside(summary: dict[str, Any], bounds: tuple[float, float]) -> bool:
    """Whether an error summary's range ``[lo, hi]`` lies inside ``bounds``."""
    return bool(bounds[0] <= summary["lo"] and summary["hi"] <= bounds[1])


def seed_succeeds(row: dict[str, Any], group: str = "test_group") -> bool:
    """The thesis's bar of success for one learning row: the network's error ranges on ``group``
    inside the ranges the thesis accepts (its 150-sample result) for both outputs."""
    ref = THESIS_ERROR_RANGES[ACCEPTED_SAMPLES]
    return all(range_inside(row[group]["network"][o], ref[o]) for o in OUTPUTS)


def thesis_statement(n: int, succeeded: int, seeds: int) -> str:
    """``"thesis: fails at 50 samples / uvnav: ..."``: the thesis's verdict at ``n`` samples
    (:data:`THESIS_ACCEPTED`) beside how many of ``seeds`` runs met its bar (:func:`seed_succeeds`)
    and on how many the verdict agrees.  Being inside a range the thesis reports as a failure is
    not agreement: at 50 samples the runs that agree are those that fail too.

    Raises:
        KeyError: a sample count the thesis gives no verdict for.
    """
    ok = THESIS_ACCEPTED[n]
    agree = succeeded if ok else seeds - succeeded
    return (
        f"thesis: {'succeeds' if ok else 'fails'} at {n} samples / uvnav: succeeds on "
        f"{succeeded}/{seeds} seeds, fails on {seeds - succeeded}/{seeds}; agrees on "
        f"{agree}/{seeds}"
    )


def _row_label(targets: str, variant: str) -> str:
    return f"Ch5 BPNN (targets = {TARGET_LABELS[targets]}, variant = {variant})"


def _ties_note(rs: list[dict[str, Any]]) -> str:
    """The beam ties of the rows' test groups (true-geometry targets only), or ``""``."""
    ties = [r["test_group_beam_ties"] for r in rs if "test_group_beam_ties" in r]
    if not ties:
        return ""
    note = (
        f"; {sum(t['n'] for t in ties)} test samples whose true sensor is not argmin "
        f"(readings within {1000 * max(t['max_reading_gap'] for t in ties):.0f} mm)"
    )
    others = [o for t in ties if not math.isnan((o := t["index_error_others"])[0])]
    if others:
        lo_o, hi_o = min(o[0] for o in others), max(o[1] for o in others)
        note += f", the other samples' errors {_range(lo_o, hi_o)}"
    return note


def _error_row(label: str, n: int, out: str, rs: list[dict[str, Any]]) -> dict[str, Any]:
    """One output's test-group error range over the seeds of a (targets, variant, n) group."""
    g = [r["test_group"]["network"][out] for r in rs]
    k = len(rs)
    accepted = THESIS_ERROR_RANGES[ACCEPTED_SAMPLES][out]
    ref = THESIS_ERROR_RANGES.get(n)
    note = (
        f"median of {k} seeds; union {_range(min(x['lo'] for x in g), max(x['hi'] for x in g))}; "
        f"median MAE {np.median([x['mae'] for x in g]):.3g}"
    )
    if ref is not None and THESIS_ACCEPTED[n]:
        thesis = _range(*ref[out])
        note += (
            f"; inside the thesis's range on {sum(range_inside(x, ref[out]) for x in g)}/{k} seeds"
        )
        alls = [r["all_samples"]["network"][out] for r in rs if "all_samples" in r]
        if alls:
            inside_all = sum(range_inside(x, ref[out]) for x in alls)
            note += f" (over all {n} samples, train + validation + test: {inside_all}/{len(alls)})"
    else:
        thesis = f"{_range(*ref[out])}: a failure" if ref is not None else "-"
        note += (
            f"; within the range the thesis accepts ({ACCEPTED_SAMPLES} samples, "
            f"{_range(*accepted)}) on {sum(range_inside(x, accepted) for x in g)}/{k} seeds"
        )
        if ref is not None:
            note += "; being inside the thesis's failed range is not agreement"
    if out == "index":
        note += _ties_note(rs)
    med_lo, med_hi = float(np.median([x["lo"] for x in g])), float(np.median([x["hi"] for x in g]))
    return table_row(
        f"{label} {n} samples: {out} error, test group",
        thesis,
        f"median {_range(med_lo, med_hi)}",
        note,
    )


def _mae_row(label: str, n: int, out: str, rs: list[dict[str, Any]]) -> dict[str, Any]:
    """One output's MAE on the independent test set, network and min/argmin baseline."""
    ind = [r["independent"]["network"][out]["mae"] for r in rs]
    base = [r["independent"]["baseline"][out]["mae"] for r in rs]
    note = (
        f"{rs[0]['independent']['network'][out]['n']} samples; median of {len(rs)} seeds; "
        "baseline = min/argmin of the raw readings"
    )
    if str(rs[0].get("targets", "geometry")) == "readings":
        note += " (the targets themselves are min/argmin of the inputs, exact in one line)"
    if out == "index":
        right = np.median([r["independent"]["network"]["index_accuracy"] for r in rs])
        right_b = np.median([r["independent"]["baseline"]["index_accuracy"] for r in rs])
        note += f"; sensor named right: network {right:.1%}, baseline {right_b:.1%}"
    return table_row(
        f"{label} {n}: {out} MAE, indep. test (baseline)",
        "-",
        f"{np.median(ind):.3g} ({np.median(base):.3g})",
        note,
    )


def _learning_rows(label: str, n: int, rs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The table rows of one (targets, variant, sample count) group of learning rows."""
    rows = [_error_row(label, n, out, rs) for out in OUTPUTS]
    if n in THESIS_ACCEPTED:
        ok = sum(seed_succeeds(r) for r in rs)
        ref = THESIS_ERROR_RANGES[ACCEPTED_SAMPLES]
        rows.append(
            table_row(
                f"{label} {n} samples: outcome",
                "succeeds (acceptable)" if THESIS_ACCEPTED[n] else "fails (too scattered)",
                f"succeeds on {ok}/{len(rs)} seeds",
                f"{thesis_statement(n, ok, len(rs))}; success = both test-group error "
                f"ranges inside the thesis's accepted {ACCEPTED_SAMPLES}-sample ranges "
                f"{_range(*ref['distance'])} and {_range(*ref['index'])}",
            )
        )
    return rows + [_mae_row(label, n, out, rs) for out in OUTPUTS]


def learning_table(learning: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Rows "thesis reported vs uvnav measured" of the learning rows ``learning`` (measured
    rows only).

    Learning rows are labelled by their targets (the thesis's min/argmin of the inputs, first,
    or the true geometry) and network variant.  At a sample count the thesis reports as a
    failure (50) the comparison is the thesis's verdict (:func:`thesis_statement`), never
    "inside its range".
    """
    rows: list[dict[str, Any]] = []
    groups: dict[tuple[int, int, int], list[dict[str, Any]]] = {}
    t_order = {t: i for i, t in enumerate(("readings", "geometry"))}
    v_order = {v: i for i, v in enumerate(VARIANT_LABELS)}
    for r in learning:
        t, v = str(r.get("targets", "geometry")), str(r["variant"])
        groups.setdefault((t_order[t], v_order[v], int(r["samples"])), []).append(r)
    for (_t, _v, n), rs in sorted(groups.items()):
        label = _row_label(str(rs[0].get("targets", "geometry")), str(rs[0]["variant"]))
        rows += _learning_rows(label, n, rs)
    return rows


def json_default(x: Any) -> Any:
    """``json.dumps``'s ``default``: numpy scalars as Python numbers, a non-finite float as null."""
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    raise TypeError(type(x).__name__)
