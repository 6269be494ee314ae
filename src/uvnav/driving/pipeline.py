"""The Chapter 6 pipeline: dataset → balanced split → trained CNN → closed-loop evaluation, DAgger.

It joins the driving parts of this package (data, simulator, expert, evaluator) with the network
of :mod:`uvnav.learning`, imported when a function needs it: a learned policy sees only what the
car's camera and speedometer give — the frame and the speed — while the expert (an oracle) reads
the pose and track.

DAgger (Ross, Gordon & Bagnell, "A Reduction of Imitation Learning and Structured Prediction to
No-Regret Online Learning", AISTATS 2011), beyond the thesis: the network drives, the expert
labels the states the network visits, the new rows join the dataset, and the network is trained
again; plain behaviour cloning only ever sees the expert's own states.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from uvnav.driving.collect import dataset_meta, write_expert_row
from uvnav.driving.dataset import (
    LogWriter,
    balance_indices,
    expand_cameras,
    load_images,
    read_log,
    split_indices,
    steering_histogram,
)
from uvnav.driving.evaluate import (
    EpisodeResult,
    PISpeedController,
    Policy,
    expert_policy,
    run_closed_loop,
    speed_law_throttle,
    with_pi_throttle,
)
from uvnav.driving.expert import PurePursuitExpert
from uvnav.driving.sim import DrivingSim, Telemetry
from uvnav.learning.config import PilotNetConfig, TrainConfig

#: the closed loop's throttle: the network's throttle head ("learned", the thesis's), the
#: proportional law tracking the network's target-speed output ("learned-speed"), or a PI to a
#: constant set speed ("pi", Udacity's drive.py)
Throttle = Literal["learned", "learned-speed", "pi"]
THROTTLE_MODES: tuple[str, ...] = ("learned", "learned-speed", "pi")


@dataclass
class PreparedData:
    """A dataset after camera expansion, balancing and the 8:2 split (arrays in memory).

    ``train``/``val`` are ``(images, steering, throttle, speed)``; ``target_speed_train`` /
    ``target_speed_val`` the expert's target speed [m/s] of the same samples (``None`` when the
    log has no target_speed column).
    """

    steering_all: NDArray[np.float64]
    steering_balanced: NDArray[np.float64]
    train: tuple[NDArray[np.uint8], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    val: tuple[NDArray[np.uint8], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    n_rows: int
    n_frames: int
    info: dict[str, Any] = field(default_factory=dict)
    target_speed_train: NDArray[np.float64] | None = None
    target_speed_val: NDArray[np.float64] | None = None
    #: camera of each validation sample (:data:`uvnav.driving.dataset.CAMERA_NAMES` indices)
    camera_val: NDArray[np.int8] | None = None


def prepare_data(
    root: Path | str,
    *,
    correction: float = 0.2,
    n_bins: int = 25,
    max_per_bin: int | None = 200,
    val_fraction: float = 0.2,
    seed: int = 0,
    size: tuple[int, int] = (66, 200),
    sides: bool = True,
    exact_sides: bool = True,
) -> PreparedData:
    """Read a Udacity-layout folder, expand cameras, balance (Fig. 6.5) and split (Fig. 6.6).

    Args:
        root: dataset folder.
        correction: left/right steering correction.
        n_bins: histogram bins.
        max_per_bin: balancing threshold (``None``: no balancing).
        val_fraction: validation share (thesis: 0.2).
        seed: seed of balancing and split.
        size: network input (H, W).
        sides: use the left/right images (False for top-down datasets).
        exact_sides: label side images with the log's exact side labels where it has them
            (False: ``± correction`` everywhere, the thesis's recipe).

    Returns:
        The prepared arrays and counts; ``info["side_labels"]`` says which side labels were
        used (``"exact"``, ``"correction"``, ``"mixed"`` or ``"none"``).
    """
    rng = np.random.default_rng([seed, 66])
    log = read_log(root)
    samples = expand_cameras(log, correction=correction, sides=sides, exact_sides=exact_sides)
    keep = (
        balance_indices(samples.steering, rng, n_bins=n_bins, max_per_bin=max_per_bin)
        if max_per_bin
        else np.arange(len(samples))
    )
    bal = samples.take(keep)
    tr, va = split_indices(len(bal), rng, val_fraction=val_fraction)
    imgs = load_images(bal.paths, size=size)

    def part(idx: NDArray[np.int64]) -> Any:
        return (imgs[idx], bal.steering[idx], bal.throttle[idx], bal.speed[idx])

    counts, _ = steering_histogram(samples.steering, n_bins=n_bins)
    ts = bal.target_speed
    return PreparedData(
        steering_all=samples.steering,
        steering_balanced=bal.steering,
        train=part(tr),
        val=part(va),
        n_rows=len(log),
        n_frames=len(samples),
        info={
            "steering_mean": float(samples.steering.mean()),
            "steering_std": float(samples.steering.std()),
            "max_bin_before": int(counts.max()),
            "n_balanced": len(bal),
            "n_train": len(tr),
            "n_val": len(va),
            "side_labels": _side_label_kind(log, sides=sides, exact_sides=exact_sides),
            "camera_fov_deg": dataset_meta(root).get("fov_deg"),
        },
        target_speed_train=None if ts is None else ts[tr],
        target_speed_val=None if ts is None else ts[va],
        camera_val=None if bal.camera is None else bal.camera[va],
    )


def _side_label_kind(log: Any, *, sides: bool, exact_sides: bool) -> str:
    """Which side labels :func:`expand_cameras` used: exact, correction, mixed or none."""
    if not sides:
        return "none"
    if not exact_sides or log.steering_left is None or log.steering_right is None:
        return "correction"
    have = ~(np.isnan(log.steering_left) | np.isnan(log.steering_right))
    return "exact" if have.all() else "mixed"


def _labelled(data: PreparedData, net: PilotNetConfig) -> tuple[Any, Any]:
    """``(train, val)`` with the third array the network's second-output label."""
    if not net.predicts_target_speed:
        return data.train, data.val
    from uvnav.learning.pilotnet import target_speed_label

    if data.target_speed_train is None or data.target_speed_val is None:
        raise ValueError(
            "target_speed: the dataset has no target_speed column (8th column of "
            "driving_log.csv, written by `uvnav drive collect`); train the throttle head instead"
        )
    im, st, _, sp = data.train
    vim, vst, _, vsp = data.val
    return (
        (im, st, target_speed_label(data.target_speed_train, net), sp),
        (vim, vst, target_speed_label(data.target_speed_val, net), vsp),
    )


def train_on(
    data: PreparedData,
    out: Path | str,
    *,
    net: PilotNetConfig | None = None,
    config: TrainConfig | None = None,
    model: Any = None,
    on_epoch: Callable[[int, float, float], None] | None = None,
) -> tuple[Any, dict[str, Any]]:
    """Train on prepared data and save the checkpoint ``out`` (safetensors + JSON).

    The second output is trained on the throttle or, for ``net.second_output ==
    "target_speed"``, on the expert's scaled target speed; ``val_throttle_mse`` is that second
    output's term either way (``second_output`` in the record says which), and for a target-speed
    network ``val_target_speed_rmse`` gives it in [m/s].

    Interruptible: the state after each epoch is kept in :func:`training_state_path` of ``out``
    and a rerun on the same data and settings continues from the last finished epoch.

    Returns:
        ``(model, record)`` with the loss curves, data counts and timing in ``record``
        (``cpu_s`` and ``images_per_s`` are those of this call's epochs).
    """
    from uvnav.learning.checkpoint import save_checkpoint
    from uvnav.learning.train import train_pilotnet

    ncfg: PilotNetConfig = model.config if model is not None else (net or PilotNetConfig())
    train, val = _labelled(data, ncfg)
    out = Path(out)
    state = training_state_path(out)
    tic = time.process_time()
    model, hist = train_pilotnet(
        train, val, net=ncfg, config=config, model=model, on_epoch=on_epoch, resume=state
    )
    cpu_s = time.process_time() - tic
    second = ncfg.second_output if ncfg.n_outputs == 2 else "none"
    record = {
        "second_output": second,
        "train_loss": hist.train_loss,
        "val_loss": hist.val_loss,
        "val_steering_mse": hist.val_steering_mse,
        "val_throttle_mse": hist.val_throttle_mse,
        "val_target_speed_rmse": [
            float(np.sqrt(m)) * ncfg.speed_scale for m in hist.val_throttle_mse
        ]
        if second == "target_speed"
        else [],
        "val_steering_mse_by_camera": steering_mse_by_camera(model, data, val),
        "images_per_s": hist.images_per_s,
        "cpu_s": cpu_s,
        "n_rows": data.n_rows,
        "n_frames": data.n_frames,
        **data.info,
    }
    save_checkpoint(model, out, record=record)
    state.unlink(missing_ok=True)
    return model, record


def training_state_path(checkpoint: Path | str) -> Path:
    """Where :func:`train_on` keeps the per-epoch training state of ``checkpoint`` until the
    model is saved (an interrupted training continues from its last finished epoch)."""
    p = Path(checkpoint)
    return p.with_name(p.stem + ".train-state.safetensors")


def steering_mse_by_camera(model: Any, data: PreparedData, val: Any = None) -> dict[str, float]:
    """Validation steering MSE of the trained network on each camera's images (eval mode).

    Args:
        model: trained network.
        data: prepared data (its ``camera_val``; an empty dict when unknown).
        val: the validation tuple with the network's labels (default ``data.val``).

    Returns:
        ``{"centre": mse, "left": mse, "right": mse}`` for the cameras present.
    """
    from uvnav.driving.dataset import CAMERA_NAMES
    from uvnav.learning.train import evaluate_mse

    if data.camera_val is None:
        return {}
    im, st, second, sp = data.val if val is None else val
    out: dict[str, float] = {}
    for k, name in enumerate(CAMERA_NAMES):
        idx = np.flatnonzero(data.camera_val == k)
        if len(idx):
            out[name] = evaluate_mse(model, im[idx], st[idx], second[idx], sp[idx])[1]
    return out


def fit_target_speed_readout(
    model: Any,
    data: PreparedData,
    *,
    target_speed_max: float | None = None,
    ridge: float = 1e-3,
) -> tuple[Any, dict[str, Any]]:
    """Give a trained network a target-speed output by a linear readout, without retraining.

    The output layer reads 10 hidden units; its steering row is kept, and its second row (the
    throttle's) is replaced by the ridge least-squares fit of the scaled target-speed label
    (:func:`uvnav.learning.pilotnet.target_speed_label`) on those units over the training split
    (eval mode, no augmentation).  Everything the steering depends on is unchanged, so the
    network steers exactly as before; the hidden units already carry the road ahead and the speed
    (they were trained to predict the expert's throttle, ``clip(k (v_target − v))``).

    Args:
        model: a trained two-output network with the speed input.
        data: prepared data with the target_speed column (the same split as its training).
        target_speed_max: label cap [m/s] (default: :class:`PilotNetConfig`'s).
        ridge: ridge regularisation of the least squares.

    Returns:
        ``(new model, record)``; the record has the validation MSE of both outputs (the second
        in label units), the target speed RMSE [m/s] and the R² of the readout.
    """
    import torch

    from uvnav.learning.pilotnet import build_pilotnet, target_speed_label
    from uvnav.learning.train import evaluate_mse, hidden_features

    cfg: PilotNetConfig = model.config
    if cfg.n_outputs != 2:
        raise ValueError("fit_target_speed_readout: the network has no second output")
    if data.target_speed_train is None or data.target_speed_val is None:
        raise ValueError(
            "target_speed: the dataset has no target_speed column (8th column of "
            "driving_log.csv, written by `uvnav drive collect`)"
        )
    new_cfg = PilotNetConfig.from_dict(
        {
            **cfg.to_dict(),
            "second_output": "target_speed",
            "target_speed_max": target_speed_max or PilotNetConfig.target_speed_max,
        }
    )
    new: Any = build_pilotnet(new_cfg)
    new.load_state_dict(model.state_dict())
    f_tr = hidden_features(new, data.train[0], data.train[3])
    y_tr = target_speed_label(data.target_speed_train, new_cfg)
    a = np.c_[f_tr, np.ones(len(f_tr))]
    w = np.linalg.solve(a.T @ a + ridge * np.eye(a.shape[1]), a.T @ y_tr)
    with torch.no_grad():
        new.head[-1].weight[1] = torch.as_tensor(w[:-1], dtype=torch.float32)
        new.head[-1].bias[1] = float(w[-1])
    y_va = target_speed_label(data.target_speed_val, new_cfg)
    m, ms, mt = evaluate_mse(new, data.val[0], data.val[1], y_va, data.val[3])
    var = float(np.var(y_va))
    record = {
        "second_output": "target_speed",
        "readout": "ridge least squares on the last hidden layer",
        "val_loss": [m],
        "val_steering_mse": [ms],
        "val_throttle_mse": [mt],
        "val_target_speed_rmse": [float(np.sqrt(mt)) * new_cfg.speed_scale],
        "val_target_speed_r2": 1.0 - mt / var if var > 0 else float("nan"),
        "camera_fov_deg": data.info.get("camera_fov_deg"),
        "n_train": len(y_tr),
        "n_val": len(y_va),
    }
    return new.eval(), record


def cnn_policy(
    model: Any,
    *,
    throttle: Throttle = "learned",
    set_speed: float = 35.0,
    speed_factor: float = 1.0,
    max_speed: float | None = None,
    backend: str = "torch",
) -> tuple[Policy, Callable[[], None] | None]:
    """A policy from the network: it sees the frame and the speed only.

    Args:
        model: trained network.
        throttle: ``"learned"`` (the network's throttle head, the thesis's), ``"learned-speed"``
            (the network's target-speed output tracked by the expert's proportional law
            ``clip(0.15 (v̂ − v))``, :func:`uvnav.driving.evaluate.speed_law_throttle`) or
            ``"pi"`` (PI to ``set_speed``).  A steering-only network always uses the PI.
        set_speed: PI target speed [m/s].
        speed_factor: "learned-speed" only: the car tracks ``speed_factor · v̂`` (1 = the
            expert's speeds; below 1 leaves the learned steering a margin, see
            docs/thesis-notes.md).
        max_speed: "learned-speed" only: a speed limiter [m/s], the car tracks
            ``min(speed_factor · v̂, max_speed)`` (``None``: none).
        backend: inference backend, ``"torch"`` or ``"onnxruntime"``
            (:class:`uvnav.learning.train.Predictor`).

    Returns:
        ``(policy, on_reset)``; ``on_reset`` clears the PI integral (``None`` otherwise).

    Raises:
        ValueError: an unknown mode, or a mode the network's second output does not serve
            ("learned" needs a throttle head, "learned-speed" a target-speed head).
    """
    from uvnav.learning.train import Predictor

    if throttle not in THROTTLE_MODES:
        raise ValueError(f"throttle: {throttle!r} (must be one of {', '.join(THROTTLE_MODES)})")
    if not 0.0 < speed_factor <= 2.0:
        raise ValueError(f"speed_factor: {speed_factor} (must be in (0, 2])")
    if max_speed is not None and max_speed <= 0:
        raise ValueError(f"max_speed: {max_speed} (must be > 0)")
    cap = float("inf") if max_speed is None else max_speed
    cfg: PilotNetConfig = model.config
    pred = Predictor(model, backend=backend)

    def act(frame: NDArray[np.uint8], tel: Telemetry) -> tuple[float, float]:
        return pred.outputs(frame, tel.speed)

    if throttle == "pi" or cfg.n_outputs == 1:
        pi = PISpeedController(set_speed=set_speed)
        return with_pi_throttle(act, pi), pi.reset
    if throttle == "learned-speed":
        if not cfg.predicts_target_speed:
            raise ValueError(
                "throttle 'learned-speed' needs a network trained on the target speed "
                "(second_output='target_speed'); this one has a throttle head: use 'learned'"
            )

        def act_speed(frame: NDArray[np.uint8], tel: Telemetry) -> tuple[float, float]:
            steer, v_hat = pred.outputs(frame, tel.speed)
            return steer, speed_law_throttle(min(speed_factor * v_hat, cap), tel.speed)

        return act_speed, None
    if cfg.predicts_target_speed:
        raise ValueError(
            "throttle 'learned' needs a throttle head; this network predicts the target "
            "speed: use 'learned-speed'"
        )
    return act, None


def default_learned_mode(model: Any) -> Throttle:
    """The learned throttle mode a network serves: "learned-speed" or "learned"."""
    return "learned-speed" if model.config.predicts_target_speed else "learned"


def evaluate(
    policy: Policy,
    seeds: Sequence[int],
    *,
    on_reset: Callable[[], None] | None = None,
    max_steps: int = 2000,
    sim: DrivingSim | None = None,
    on_episode: Callable[[EpisodeResult], None] | None = None,
) -> list[EpisodeResult]:
    """Closed-loop episodes of a policy on the front camera, one per seed."""
    own = sim is None
    sim = sim or DrivingSim(max_steps=max_steps)
    out = []
    try:
        for s in seeds:
            r = run_closed_loop(sim, policy, int(s), max_steps=max_steps, on_reset=on_reset)
            out.append(r)
            if on_episode is not None:
                on_episode(r)
    finally:
        if own:
            sim.close()
    return out


def evaluate_expert(seeds: Sequence[int], *, max_steps: int = 2000) -> list[EpisodeResult]:
    """Closed-loop episodes of the (oracle) expert, the reference of the return ratio."""
    sim = DrivingSim(max_steps=max_steps)
    try:
        return evaluate(expert_policy(sim), seeds, sim=sim, max_steps=max_steps)
    finally:
        sim.close()


def dagger_collect(
    model: Any,
    root: Path | str,
    seeds: Sequence[int],
    *,
    round_id: int,
    beta: float = 0.0,
    record_every: int = 4,
    max_steps: int = 1200,
    throttle: Throttle = "pi",
    set_speed: float = 35.0,
) -> int:
    """One DAgger round's data: the network drives (mixed with the expert by ``beta``), the
    expert labels every recorded state, rows are appended to the dataset.

    The learner drives with the throttle it is evaluated with (``throttle``): with ``"pi"`` the
    visited states are those of the PI-throttle closed loop, whose failures are in the steering
    (measured: under-steer in the sharpest corners and no recovery from near the road's edge).

    Args:
        model: current network.
        root: dataset folder (rows appended).
        seeds: training tracks to drive (never the held-out evaluation tracks).
        round_id: used in the image names.
        beta: probability per step that the expert's command is applied instead.
        record_every: record every this many steps.
        max_steps: steps per episode.
        throttle: the learner's throttle: ``"pi"`` (PI to ``set_speed``), ``"learned"`` or
            ``"learned-speed"`` (then the states visited include the learner's own speed
            mistakes, e.g. too fast before corners, and the expert labels them).
        set_speed: PI target speed [m/s].

    Returns:
        Rows written.
    """
    learner, on_reset = cnn_policy(model, throttle=throttle, set_speed=set_speed)
    sim = DrivingSim(max_steps=max_steps)
    writer = LogWriter(root)
    rows = 0
    try:
        for seed in seeds:
            rng = np.random.default_rng([seed, round_id, 7])
            frame, tel = sim.reset(int(seed))
            if on_reset is not None:
                on_reset()
            assert sim.geometry is not None
            expert = PurePursuitExpert(sim.geometry)
            for k in range(max_steps):
                label = expert.label(tel)
                e_steer, e_thr, _ = label
                if k % record_every == 0:
                    name = f"d{round_id}_{seed:05d}_{k:05d}"
                    write_expert_row(writer, name, sim, expert, tel, label)
                    rows += 1
                steer, thr = (e_steer, e_thr) if rng.random() < beta else learner(frame, tel)
                st = sim.step_on_track(steer, thr)
                frame, tel = st.frame, st.telemetry
                if st.terminated or st.truncated:
                    break
            writer.flush()
    finally:
        writer.close()
        sim.close()
    return rows


@dataclass
class DaggerRound:
    """One DAgger round: rows added, the model after it, and its closed-loop means."""

    round_id: int
    rows: int
    model_path: Path
    record: dict[str, Any]
    summary: dict[str, float]


def dagger_round(
    model: Any,
    root: Path | str,
    out_dir: Path | str,
    *,
    round_id: int,
    episodes: int,
    epochs: int,
    first_seed: int = 600,
    throttle: Throttle = "pi",
    set_speed: float = 35.0,
    collect_steps: int = 1500,
    threads: int = 1,
    progress: Callable[[str], None] | None = None,
) -> tuple[Any, int, Path, dict[str, Any]]:
    """One DAgger round without its evaluation: drive, aggregate, fine-tune, save.

    Round ``round_id`` drives tracks ``first_seed + (round_id − 1)·episodes …`` (disjoint from
    the demonstrations' seeds 0… and from the held-out evaluation tracks), appends the
    expert-labelled rows to ``root``, rebalances and resplits the aggregate, and continues
    training ``model`` on it for ``epochs`` (warm start; Ross et al. retrain on the aggregate).

    Returns:
        ``(model, rows added, checkpoint path out_dir/dagger{round_id}.safetensors, record)``.
    """
    say = progress or (lambda s: None)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    r = round_id
    seeds = range(first_seed + (r - 1) * episodes, first_seed + r * episodes)
    say(f"DAgger round {r}: the network drives {episodes} training tracks ({throttle} throttle)")
    rows = dagger_collect(
        model,
        root,
        seeds,
        round_id=r,
        throttle=throttle,
        set_speed=set_speed,
        max_steps=collect_steps,
    )
    data = prepare_data(root)
    say(f"DAgger round {r}: training {epochs} epochs on {data.info['n_train']} images")
    path = out / f"dagger{r}.safetensors"
    model, record = train_on(
        data, path, model=model, config=TrainConfig(epochs=epochs, threads=threads)
    )
    return model, rows, path, record


def run_dagger(
    model: Any,
    root: Path | str,
    out_dir: Path | str,
    *,
    rounds: int,
    episodes: int,
    epochs: int,
    eval_seeds: Sequence[int],
    first_seed: int = 600,
    throttle: Throttle = "pi",
    set_speed: float = 35.0,
    collect_steps: int = 1500,
    max_steps: int = 2000,
    threads: int = 1,
    progress: Callable[[str], None] | None = None,
) -> tuple[Any, list[DaggerRound]]:
    """DAgger rounds: drive ``episodes`` training tracks, aggregate, fine-tune, evaluate.

    Each round is :func:`dagger_round` followed by a closed loop on ``eval_seeds``.  The
    resplit means a round's validation MSE is not a clean hold-out (images trained on before
    may land in it): the measure of a round is the closed loop on the held-out tracks.

    Args:
        model: starting network (round 0, e.g. the behaviour-cloning one).
        root: dataset folder (rows are appended).
        out_dir: folder of ``dagger{r}.safetensors``.
        rounds: DAgger rounds.
        episodes: tracks driven per round.
        epochs: training epochs per round.
        eval_seeds: held-out tracks evaluated after each round.
        first_seed: first training track of round 1.
        throttle: the learner's throttle while driving and when evaluated.
        set_speed: PI target speed [m/s].
        collect_steps: steps per DAgger episode.
        max_steps: closed-loop step limit of the evaluation.
        threads: torch CPU threads for training.
        progress: called with a one-line status before each stage.

    Returns:
        ``(final model, rounds)``.
    """
    from uvnav.driving.evaluate import summarize

    say = progress or (lambda s: None)
    done: list[DaggerRound] = []
    for r in range(1, rounds + 1):
        model, rows, path, record = dagger_round(
            model,
            root,
            out_dir,
            round_id=r,
            episodes=episodes,
            epochs=epochs,
            first_seed=first_seed,
            throttle=throttle,
            set_speed=set_speed,
            collect_steps=collect_steps,
            threads=threads,
            progress=say,
        )
        say(f"DAgger round {r}: closed loop on {len(eval_seeds)} held-out tracks")
        policy, on_reset = cnn_policy(model, throttle=throttle, set_speed=set_speed)
        summary = summarize(evaluate(policy, eval_seeds, on_reset=on_reset, max_steps=max_steps))
        done.append(DaggerRound(r, rows, path, record, summary))
    return model, done
