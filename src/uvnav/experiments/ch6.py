"""Reproduction of thesis Chapter 6 (a CNN that drives): collect, balance, train, drive.

The chain (each stage a row of the closed-loop table, evaluated on the same held-out tracks):

1. **Behaviour cloning, the thesis's recipe**: expert demonstrations, balancing (Fig. 6.5), the
   8:2 split, PilotNet with the throttle head, Adam, batch 100.  Rows ``cnn-learned`` (the
   thesis's learned pedal head) and ``cnn-pi`` (the same steering, PI throttle to 35 m/s, as
   Udacity's drive.py).
2. **Target-speed readout** (``readout=True``, beyond the thesis): a ridge readout of the
   expert's target speed on the network's 10 last hidden units
   (:func:`uvnav.driving.pipeline.fit_target_speed_readout`; the steering is unchanged),
   driven by the "learned-speed" throttle (the expert's proportional law tracking the predicted
   speed).  Row ``cnn-learned-speed``.
3. **DAgger** (``dagger_rounds``, beyond the thesis; Ross et al. 2011): the network drives
   training tracks 600… with the learned-speed throttle, the expert relabels the visited states,
   5 epochs of fine-tuning on the aggregate.  Rows ``dagger{r}-learned-speed``.
4. The (oracle) **expert**, the reference of ``return_vs_expert``.  Row ``expert``.

Measured on 20 held-out tracks (docs/thesis-notes.md), with the network trained on 12 episodes:
the pedal head drives at autonomy 0.00 (it does not brake for corners), PI 1.00, the readout
0.947, and one DAgger round with the learned-speed throttle 1.00 (also on 20 further unseen
tracks); in the ``--full`` run itself (20 episodes): 0.00, 1.00, 1.00 and 0.986 with the fixed
±0.2 side-camera correction, 0.00, 1.00, 0.939 and 1.00 with the exact side labels the
recorder writes, and 0.00, 1.00, 1.00 and 0.926 with them and the 120° camera (the default;
validation steering MSE 0.041).
``head="target_speed"`` trains the second output on the target speed directly instead (rows
``cnn-learned-speed``, ``cnn-pi``, then the DAgger rows; no readout stage).

Sizes.  Quick (``full=False``; also ``uvnav run``'s quick mode, with the smaller
:data:`RUN_QUICK` size): a few expert episodes, 3 epochs, 3 held-out tracks, no DAgger — a few
CPU minutes, numbers that do not meet the targets and are labelled as the quick size.
``full=True`` (``uvnav drive reproduce --full``, ``uvnav run --full``): the thesis-size
experiment — 20 episodes (about 18,000 frames before balancing; the thesis had 17,592), 30 epochs,
:data:`FULL_DAGGER_ROUNDS` DAgger round, 20 held-out tracks.

Resumable: every stage — the expert's recording, training, readout, DAgger round, each closed
loop — is a stage of the results folder's stage cache (:class:`uvnav.bench.stages.StageCache`,
names ``ch6-data``, ``ch6-train``, ``ch6-readout``, ``ch6-dagger{r}``, ``ch6-<row>``), keyed by
its settings and the stages it builds on, and stored (dataset, checkpoint, record) once it
finished; a rerun with the same settings reuses the finished stages, an interrupted recording or
training continues where it stopped, and a stage made by other code (:func:`fingerprint`) is
refused unless ``fresh=True``, which remakes every stage.

Figures are drawn by the caller from the returned :class:`Ch6Summary`
(:func:`uvnav.viz.figures_ch6.render_ch6`), since figures live in the ``viz`` layer.
"""

from __future__ import annotations

import json
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from uvnav.bench.stages import STAGES_DIR, Stage, StageCache, stage_fingerprint
from uvnav.stages import write_atomic

THESIS_VAL_MSE = 0.05
THESIS_FRAMES = 17592
THESIS_TRAIN, THESIS_VAL = 1199, 300
#: the thesis's statistics of the recorded steering angle (§6.3, Fig. 6.4): min, max, mean, std
THESIS_STEERING = (-1.0, 1.0, -0.009, 0.204)
#: DAgger rounds of the full run: one, driven with the learned-speed throttle (measured on the 20
#: held-out tracks from a 12-episode network: the readout alone 0.947 autonomy, after one round
#: 1.00, and 1.00 on 20 more unseen tracks; in the 20-episode ``--full`` runs the readout alone
#: reached 1.00, 0.939, 1.00, and the round 0.986, 1.00, 0.926: within the run-to-run spread;
#: docs/thesis-notes.md);
#: ``dagger_rounds`` overrides it
FULL_DAGGER_ROUNDS = 1
#: training tracks the network drives per DAgger round, and epochs per round
DAGGER_EPISODES, DAGGER_EPOCHS = 6, 5
#: sizes of the quick (``full=False``) and full runs: expert episodes, steps per episode, epochs,
#: held-out tracks, closed-loop step limit
QUICK: dict[str, Any] = {
    "episodes": 3,
    "collect_steps": 600,
    "epochs": 3,
    "eval_seeds": [1000, 1001, 1002],
    "max_steps": 2000,
}
FULL: dict[str, Any] = {
    "episodes": 20,
    "collect_steps": 1200,
    "epochs": 30,
    "eval_seeds": list(range(1000, 1020)),
    "max_steps": 2000,
}
#: the size of ``uvnav run``'s quick mode: fewer episodes and tracks than :data:`QUICK`, to
#: add only a couple of CPU minutes (measured in docs/thesis-notes.md); its closed-loop numbers
#: are far from the targets (a network after 3 epochs on ~600 images)
RUN_QUICK: dict[str, Any] = {
    "episodes": 2,
    "collect_steps": 500,
    "epochs": 3,
    "eval_seeds": [1000, 1001],
    "max_steps": 2000,
}


@dataclass
class Ch6Summary:
    """What the Chapter 6 reproduction measured (everything a figure or table needs)."""

    table: list[dict[str, str]]
    closed_loop: dict[str, dict[str, float]]
    record: dict[str, Any]
    #: per closed-loop row, each held-out track's metrics (:meth:`EpisodeResult.to_dict`)
    tracks: dict[str, list[dict[str, Any]]]
    steering_all: NDArray[np.float64]
    steering_balanced: NDArray[np.float64]
    steering_train: NDArray[np.float64]
    steering_val: NDArray[np.float64]
    views: list[NDArray[np.uint8]]
    augment_examples: list[tuple[str, NDArray[np.uint8], NDArray[np.uint8], str]]
    model_path: Path
    wall_time: float = 0.0
    figures: list[Path] = field(default_factory=list)
    #: records of the later stages (``readout``, ``dagger{r}``): validation MSE etc.
    stage_records: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: stages skipped because ``stages/`` had them (a resumed run)
    reused: list[str] = field(default_factory=list)
    #: the run's size: ``episodes``, ``collect_steps``, ``epochs``, ``eval_seeds``, ``max_steps``
    size: dict[str, Any] = field(default_factory=dict)


def augmentation_examples(
    image: NDArray[np.uint8], steering: float, seed: int = 0
) -> list[tuple[str, NDArray[np.uint8], NDArray[np.uint8], str]]:
    """Fig. 6.7's three rows: flip (steering negated), brightness, zoom — by the training code."""
    import torch

    from uvnav.learning.augment import augment_batch

    g = torch.Generator().manual_seed(seed)
    x = torch.as_tensor(image[None]).float()
    s = torch.tensor([steering])
    out = []
    for name, kw in (
        ("flip", {"flip_prob": 1.0, "brightness": (1.0, 1.0), "zoom": (1.0, 1.0)}),
        ("brightness", {"flip_prob": 0.0, "brightness": (0.6, 0.6), "zoom": (1.0, 1.0)}),
        ("zoom", {"flip_prob": 0.0, "brightness": (1.0, 1.0), "zoom": (1.3, 1.3)}),
    ):
        xa, sa = augment_batch(x, s, g, **kw)  # type: ignore[arg-type]
        cap = f"steering {steering:+.2f} -> {float(sa[0]):+.2f}"
        out.append((name, image, xa[0].clamp(0, 255).byte().numpy(), cap))
    return out


#: the stage names of this experiment in the results folder's stage cache
DATA, TRAIN, READOUT, EXPERT = "ch6-data", "ch6-train", "ch6-readout", "ch6-expert"


def fingerprint() -> str:
    """The code that makes this experiment's stages: :mod:`uvnav.driving`, :mod:`uvnav.learning`,
    this module, and the numpy, torch and gymnasium versions."""
    return stage_fingerprint(
        "driving", "learning", "experiments/ch6.py", packages=("numpy", "torch", "gymnasium")
    )


def _log_rows(root: Path) -> int:
    """Rows of a dataset's ``driving_log.csv`` (0 when absent)."""
    from uvnav.driving.dataset import LOG_NAME

    f = root / LOG_NAME
    if not f.is_file():
        return 0
    with f.open(newline="") as fh:
        return sum(1 for line in fh if line.strip())


def _per_lap(row: dict[str, float]) -> None:
    """Add ``interventions_per_lap`` (mean interventions over mean laps; inf when no lap)."""
    laps = row.get("laps", 0.0)
    n = row.get("interventions", 0.0)
    row["interventions_per_lap"] = n / laps if laps > 0 else (0.0 if n == 0 else float("inf"))


def _say_stage(say: Callable[[str], None], stage: Stage, what: str) -> None:
    if stage.reused:
        say(f"{what}: done before ({STAGES_DIR}/{stage.key})")


def _dataset(
    cache: StageCache,
    n_ep: int,
    c_steps: int,
    noise_sigma: float | None,
    say: Callable[[str], None],
) -> Stage:
    """The expert's recording (stage :data:`DATA`: ``data/`` in its folder; an interrupted
    recording resumes at its first unrecorded episode)."""
    from uvnav.driving.collect import CollectParams, collect, dataset_meta, recording_meta
    from uvnav.driving.sim import DrivingSim

    cp = (
        CollectParams(max_steps=c_steps)
        if noise_sigma is None
        else CollectParams(max_steps=c_steps, noise_sigma=noise_sigma)
    )
    sim = DrivingSim(max_steps=cp.max_steps)
    try:
        inputs = {"episodes": n_ep, "collect_steps": c_steps, **recording_meta(sim, cp)}

        def record(work: Path) -> dict[str, Any]:
            say(f"collecting {n_ep} expert episodes")
            collect(work / "data", range(n_ep), params=cp, sim=sim)
            return {"rows": _log_rows(work / "data"), **dataset_meta(work / "data")}

        stage = cache.run(DATA, inputs, record)
    finally:
        sim.close()
    _say_stage(say, stage, "expert recording")
    return stage


def _network(
    cache: StageCache, name: str, inputs: dict[str, Any], file: str, build: Callable[[Path], Any]
) -> tuple[Any, Stage]:
    """A stage whose product is the checkpoint ``file`` (``build(work)`` writes it and returns
    the record): ``(the network loaded from the stage, the stage)``."""
    from uvnav.learning.checkpoint import load_checkpoint

    stage = cache.run(name, inputs, build)
    model, _ = load_checkpoint(stage.folder / file)
    return model, stage


def _dagger(
    cache: StageCache,
    learner: Any,
    learner_stage: Stage,
    data_stage: Stage,
    r: int,
    params: dict[str, Any],
    threads: int,
    say: Callable[[str], None],
) -> tuple[Any, Stage]:
    """DAgger round ``r`` (stage ``ch6-dagger{r}``): the aggregate ``data/`` (a copy of the
    previous round's, or of the expert's, plus this round's rows) and ``dagger{r}.safetensors``.
    An interrupted round starts over."""
    from uvnav.driving.pipeline import dagger_round

    def build(work: Path) -> dict[str, Any]:
        shutil.rmtree(work)
        work.mkdir()
        shutil.copytree(data_stage.folder / "data", work / "data")
        _, added, _, rec = dagger_round(
            learner, work / "data", work, round_id=r, episodes=params["episodes"],
            epochs=params["epochs"], throttle=params["throttle"],
            collect_steps=params["collect_steps"], threads=threads, progress=say,
        )  # fmt: skip
        return {"rows_added": added, "rows_after": _log_rows(work / "data"), "record": rec}

    inputs = {"model": learner_stage.ref, "data": data_stage.ref, **params}
    model, stage = _network(cache, f"ch6-dagger{r}", inputs, f"dagger{r}.safetensors", build)
    _say_stage(say, stage, f"DAgger round {r}")
    return model, stage


def reproduce_ch6(
    out_dir: Path | str,
    *,
    full: bool = False,
    episodes: int | None = None,
    epochs: int | None = None,
    eval_seeds: list[int] | None = None,
    max_steps: int | None = None,
    collect_steps: int | None = None,
    dagger_rounds: int | None = None,
    dagger_episodes: int | None = None,
    dagger_epochs: int | None = None,
    dagger_throttle: str | None = None,
    readout: bool = True,
    threads: int = 1,
    noise_sigma: float | None = None,
    head: str = "throttle",
    fresh: bool = False,
    progress: Callable[[str], None] | None = None,
    cache: StageCache | None = None,
) -> Ch6Summary:
    """Run the Chapter 6 experiment end to end (the chain in the module docstring).

    Args:
        out_dir: folder of ``ch6.json`` (and of the stage cache, unless ``cache``).
        full: thesis-size run (:data:`FULL`; otherwise :data:`QUICK`).
        episodes: override the number of expert episodes.
        epochs: override the epochs.
        eval_seeds: override the held-out tracks.
        max_steps: override the closed-loop step limit.
        collect_steps: override the steps per expert episode.
        dagger_rounds: override the DAgger rounds (default :data:`FULL_DAGGER_ROUNDS` full, 0
            quick).
        dagger_episodes: override the training tracks the network drives per DAgger round.
        dagger_epochs: override the training epochs per DAgger round.
        dagger_throttle: the learner's throttle in DAgger (driving and evaluation):
            ``"learned-speed"`` (default when the chain has a target-speed output: the readout
            or ``head="target_speed"``), ``"pi"`` (default otherwise, i.e. ``readout=False``
            with the thesis head) or ``"learned"``.
        readout: with ``head="throttle"``, fit the target-speed readout (row
            ``cnn-learned-speed``) and start DAgger from it.
        threads: torch CPU threads for training.
        noise_sigma: std of the recording's steering noise (default
            :class:`uvnav.driving.collect.CollectParams`'s; another one is another recording).
        head: the second output: ``"throttle"`` (thesis; closed loop with the "learned"
            throttle) or ``"target_speed"`` (trained directly; "learned-speed" throttle).
        fresh: remake every stage (with the default cache).
        progress: called with a one-line status before each stage.
        cache: the stage cache (default: ``out_dir``'s, made by :func:`fingerprint`).

    Returns:
        The summary (table rows "thesis vs measured", closed-loop means, arrays for figures).

    Raises:
        StaleStageError: a stage of these settings was made by other code (and not ``fresh``).
    """
    from uvnav.driving.pipeline import (
        THROTTLE_MODES,
        Throttle,
        cnn_policy,
        default_learned_mode,
        evaluate,
        evaluate_expert,
        fit_target_speed_readout,
        prepare_data,
        train_on,
    )
    from uvnav.driving.sim import DrivingSim
    from uvnav.learning import PilotNetConfig, TrainConfig
    from uvnav.learning.checkpoint import save_checkpoint

    if head not in ("throttle", "target_speed"):
        raise ValueError(f"head: {head!r} (must be throttle or target_speed)")
    if dagger_throttle is not None and dagger_throttle not in THROTTLE_MODES:
        raise ValueError(
            f"dagger_throttle: {dagger_throttle!r} (must be one of {', '.join(THROTTLE_MODES)})"
        )
    base = FULL if full else QUICK
    n_ep: int = episodes or base["episodes"]
    c_steps: int = collect_steps or base["collect_steps"]
    n_epochs: int = epochs or base["epochs"]
    seeds: list[int] = list(eval_seeds or base["eval_seeds"])
    steps: int = max_steps or base["max_steps"]
    size: dict[str, Any] = {
        "episodes": n_ep,
        "collect_steps": c_steps,
        "epochs": n_epochs,
        "eval_seeds": seeds,
        "max_steps": steps,
    }
    net = PilotNetConfig(second_output=head)
    tic = time.perf_counter()
    say = progress or (lambda s: None)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cache = cache or StageCache(out, fingerprint(), fresh=fresh)
    data_stage = _dataset(cache, n_ep, c_steps, noise_sigma, say)
    say("balancing and splitting")
    data = prepare_data(data_stage.folder / "data")
    rows: dict[str, dict[str, float]] = {}
    records: dict[str, dict[str, Any]] = {}
    tracks: dict[str, list[dict[str, Any]]] = {}

    def closed_loop(name: str, model: Any, mode: Throttle, parent: Stage) -> None:
        def drive(work: Path) -> dict[str, Any]:
            say(f"closed loop {name}, {len(seeds)} tracks")
            policy, on_reset = cnn_policy(model, throttle=mode)
            return _loop_record(evaluate(policy, seeds, on_reset=on_reset, max_steps=steps))

        key = {"model": parent.ref, "throttle": mode, "seeds": seeds, "max_steps": steps}
        stage = cache.run(f"ch6-{name}", key, drive)
        _say_stage(say, stage, f"closed loop {name}")
        rows[name], tracks[name] = dict(stage.value["summary"]), stage.value["tracks"]

    # 1. behaviour cloning (the thesis's recipe)
    def train(work: Path) -> dict[str, Any]:
        say(f"training {n_epochs} epochs on {data.info['n_train']} images")
        config = TrainConfig(epochs=n_epochs, threads=threads)
        return train_on(data, work / "model.safetensors", net=net, config=config)[1]

    inputs = {"data": data_stage.ref, "epochs": n_epochs, "head": head}
    model, train_stage = _network(cache, TRAIN, inputs, "model.safetensors", train)
    _say_stage(say, train_stage, "training")
    record: dict[str, Any] = train_stage.value
    for mode in (default_learned_mode(model), "pi"):
        closed_loop(f"cnn-{mode}", model, mode, train_stage)

    # 2. the target-speed readout (thesis head only)
    learner, learner_stage = model, train_stage
    if head == "throttle" and readout:

        def fit(work: Path) -> dict[str, Any]:
            say("target-speed readout on the last hidden layer")
            fitted, rec = fit_target_speed_readout(model, data)
            save_checkpoint(fitted, work / "readout.safetensors", record=rec)
            return rec

        inputs = {"model": train_stage.ref}
        learner, learner_stage = _network(cache, READOUT, inputs, "readout.safetensors", fit)
        _say_stage(say, learner_stage, "target-speed readout")
        records["readout"] = learner_stage.value
        closed_loop("cnn-learned-speed", learner, "learned-speed", learner_stage)

    # 3. DAgger rounds, from the learner above, each on the previous round's aggregate
    n_rounds = (FULL_DAGGER_ROUNDS if full else 0) if dagger_rounds is None else dagger_rounds
    d_mode: Throttle = dagger_throttle or (  # type: ignore[assignment]
        "learned-speed" if learner.config.predicts_target_speed else "pi"
    )
    d_params = {
        "episodes": dagger_episodes or DAGGER_EPISODES,
        "epochs": dagger_epochs or DAGGER_EPOCHS,
        "throttle": d_mode,
        "collect_steps": collect_steps or 1500,
    }
    agg = data_stage
    for r in range(1, n_rounds + 1):
        learner, agg = _dagger(cache, learner, learner_stage, agg, r, d_params, threads, say)
        learner_stage = agg
        records[f"dagger{r}"] = agg.value["record"]
        closed_loop(f"dagger{r}-{d_mode}", learner, d_mode, learner_stage)
        rows[f"dagger{r}-{d_mode}"]["rows_added"] = float(agg.value["rows_added"])

    # 4. the expert
    def expert(work: Path) -> dict[str, Any]:
        say("closed loop, expert")
        return _loop_record(evaluate_expert(seeds, max_steps=steps))

    ex = cache.run(EXPERT, {"seeds": seeds, "max_steps": steps}, expert)
    _say_stage(say, ex, "closed loop expert")
    rows["expert"], tracks["expert"] = dict(ex.value["summary"]), ex.value["tracks"]
    for row in rows.values():
        row["return_vs_expert"] = row["return"] / rows["expert"]["return"]
        _per_lap(row)

    sim = DrivingSim()
    sim.reset(seeds[0])
    views = list(sim.side_views())
    sim.close()
    k = int(np.argmax(np.abs(data.train[1]))) if len(data.train[1]) else 0
    examples = augmentation_examples(data.train[0][k], float(data.train[1][k]))
    table = _table(data, record, records, rows, size, head=head, full=full, tracks=tracks)
    wall = time.perf_counter() - tic
    write_atomic(
        out / "ch6.json",
        json.dumps(
            {
                "closed_loop": rows,
                "tracks": tracks,
                "record": record,
                "stage_records": records,
                "size": size,
                "full": full,
                "seeds": seeds,
                "head": head,
                "reused": cache.reused,
                "wall_s": wall,
            },
            indent=2,
        ),
    )
    return Ch6Summary(
        table=table,
        closed_loop=rows,
        record=record,
        tracks=tracks,
        steering_all=data.steering_all,
        steering_balanced=data.steering_balanced,
        steering_train=data.train[1],
        steering_val=data.val[1],
        views=views,
        augment_examples=examples,
        model_path=train_stage.folder / "model.safetensors",
        wall_time=wall,
        stage_records=records,
        reused=list(cache.reused),
        size=size,
    )


def steering_row(steering: NDArray[np.float64], tag: str = "") -> dict[str, str]:
    """Fig. 6.4's statistics of the recorded steering (normalised to [-1, 1]) beside the
    thesis's, and the share of frames within 0.05 of straight (its "majority ... 0 degree")."""
    st = np.asarray(steering, dtype=float)
    if st.size == 0:
        stats, near = "no frames", ""
    else:
        stats = f"{st.min():.2f} / {st.max():.2f} / {st.mean():.3f} / {st.std():.3f}"
        near = f"; {100 * float(np.mean(np.abs(st) <= 0.05)):.1f} % of frames within 0.05 of 0"
    lo, hi, mean, std = THESIS_STEERING
    return {
        "quantity": "Ch6 steering over all frames: min / max / mean / std (Fig. 6.4)" + tag,
        "thesis": f"{lo:g} / {hi:g} / {mean:g} / {std:g}",
        "measured": stats,
        "note": f"{st.size} frames, before balancing{near}",
    }


def _table(
    data: Any,
    record: dict[str, Any],
    records: dict[str, dict[str, Any]],
    rows: dict[str, dict[str, float]],
    size: dict[str, Any],
    *,
    head: str,
    full: bool,
    tracks: dict[str, list[dict[str, Any]]] | None = None,
) -> list[dict[str, str]]:
    """The "thesis vs measured" rows of a run (closed-loop notes name the tracks with
    interventions when ``tracks`` is given)."""

    def pct(x: float) -> str:
        return f"{100 * x:.1f} %"

    tag = "" if full else " [quick size]"
    n_epochs = size["epochs"]
    table = [
        {
            "quantity": "Ch6 frames before balancing" + tag,
            "thesis": str(THESIS_FRAMES),
            "measured": str(data.n_frames),
            "note": f"CarRacing-v3 + forward camera, 3 cameras, {size['episodes']} episodes",
        },
        steering_row(data.steering_all, tag),
        {
            "quantity": "Ch6 training / validation images" + tag,
            "thesis": f"{THESIS_TRAIN} / {THESIS_VAL}",
            "measured": f"{data.info['n_train']} / {data.info['n_val']}",
            "note": "25 bins, 200 per bin, 8:2 split",
        },
        {
            "quantity": "Ch6 validation MSE of the steering, eq. (6.1)" + tag,
            "thesis": f"~{THESIS_VAL_MSE}",
            "measured": f"{record['val_steering_mse'][-1]:.4f}",
            "note": f"{n_epochs} epochs; by camera "
            + (
                ", ".join(f"{k} {v:.4f}" for k, v in by_cam.items())
                if (by_cam := record.get("val_steering_mse_by_camera"))
                else "not recorded"
            )
            + f"; side-image labels: {data.info.get('side_labels', 'correction')}",
        },
        {
            "quantity": f"Ch6 validation MSE (steering + {head.replace('_', ' ')})" + tag,
            "thesis": f"~{THESIS_VAL_MSE} (Fig. 6.8, if its loss has both outputs)",
            "measured": f"{record['val_loss'][-1]:.4f}",
            "note": f"{n_epochs} epochs; "
            + (
                f"target speed RMSE {record['val_target_speed_rmse'][-1]:.1f} m/s"
                if record["val_target_speed_rmse"]
                else f"throttle only {record['val_throttle_mse'][-1]:.4f}"
            ),
        },
    ]
    for name, rec in records.items():
        extra = f", R² {rec['val_target_speed_r2']:.2f}" if "val_target_speed_r2" in rec else ""
        what = "target-speed readout" if name == "readout" else f"{name} (after DAgger)"
        table.append(
            {
                "quantity": f"Ch6 validation MSE, {what}" + tag,
                "thesis": "not reported (beyond the thesis)",
                "measured": f"{rec['val_loss'][-1]:.4f}",
                "note": f"steering only {rec['val_steering_mse'][-1]:.4f}, target speed RMSE "
                f"{rec['val_target_speed_rmse'][-1]:.1f} m/s{extra}"
                if rec.get("val_target_speed_rmse")
                else f"steering only {rec['val_steering_mse'][-1]:.4f}",
            }
        )
    ex = rows["expert"]
    for name in [k for k in rows if k != "expert"]:
        r = rows[name]
        table.append(
            {
                "quantity": f"Ch6 closed loop {name}: return vs expert / autonomy" + tag,
                "thesis": "drives without collisions",
                "measured": f"{pct(r['return_vs_expert'])} / {pct(r['autonomy'])}",
                "note": f"{len(size['eval_seeds'])} held-out tracks ({size['max_steps']} steps), "
                + (
                    f"interventions/lap {r['interventions_per_lap']:.2f}, "
                    if r["laps"] > 0
                    else f"no lap completed, {r['interventions']:.1f} interventions per track, "
                )
                + f"laps {r['laps']:.2f}, "
                f"mean speed {r['mean_speed']:.1f} m/s"
                + _intervention_tracks((tracks or {}).get(name, [])),
            }
        )
    table.append(
        {
            "quantity": "Ch6 closed loop expert (oracle): return / autonomy" + tag,
            "thesis": "(human driver)",
            "measured": f"{ex['return']:.1f} / {pct(ex['autonomy'])}",
            "note": f"laps {ex['laps']:.2f}, mean speed {ex['mean_speed']:.1f} m/s",
        }
    )
    if not full:  # a smoke-test size is not the thesis's experiment: not judged
        table = [{**row, "verdict": "-"} for row in table]
    return table


def _loop_record(episodes: list[Any]) -> dict[str, Any]:
    """A closed-loop stage's value: the means (``summary``) and each track's metrics."""
    from uvnav.driving.evaluate import summarize

    return {"summary": summarize(episodes), "tracks": [e.to_dict() for e in episodes]}


def _intervention_tracks(tracks: list[dict[str, Any]], most: int = 5) -> str:
    """``"; interventions on tracks 1007 (1), 1012 (2)"``: where a row's interventions were,
    when they were on at most ``most`` tracks (empty otherwise, or with none)."""
    hit = [(int(t["seed"]), int(t["interventions"])) for t in tracks if t["interventions"]]
    if not hit or len(hit) > most:
        return ""
    return "; interventions on tracks " + ", ".join(f"{s} ({n})" for s, n in hit)
