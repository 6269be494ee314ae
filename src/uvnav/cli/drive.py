"""``uvnav drive``: thesis Chapter 6 — collect, train, speed-head, evaluate, play, dagger,
reproduce.

Thin Typer commands over :mod:`uvnav.driving`, :mod:`uvnav.learning` and
:mod:`uvnav.driving.pipeline`.  User errors (a missing or malformed dataset or model, a bad
seed list, a missing extra) are raised as :class:`~uvnav.cli.errors.CliError`: ONE line
``error: ...`` and exit status 2 (the CLI's one error path).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer

from uvnav.cli.checks import dumps, finite, unit_range
from uvnav.cli.errors import CliError, uvnav_typer

drive_app = uvnav_typer(
    name="drive",
    help="Chapter 6: a CNN that drives (CarRacing-v3 with a forward camera).",
)


@contextmanager
def _user_errors() -> Iterator[None]:
    """The library's input errors here (a missing file, a missing extra, a malformed dataset or
    model: ``ValueError``) as :class:`CliError`; anything else propagates as a bug."""
    try:
        yield
    except FileNotFoundError as exc:
        raise CliError(f"{exc.strerror or 'not found'}: {exc.filename}") from None
    except ImportError as exc:
        raise CliError(str(exc)) from None
    except ValueError as exc:
        raise CliError(str(exc)) from None


#: the most episodes one ``--seeds`` may name (a CarRacing episode takes seconds)
MAX_SEEDS = 100_000


def parse_seeds(text: str) -> list[int]:
    """Seeds from ``"1000-1019"``, ``"1,2,5"`` or a mix (``"1-3,7"``).

    >>> parse_seeds("1-3,7")
    [1, 2, 3, 7]

    Raises:
        ValueError: a part that is not a seed ``>= 0`` or a range ``a-b`` with ``a <= b``, no
            seed at all, or more than :data:`MAX_SEEDS` of them (one line).
    """
    seeds: list[int] = []
    for part in filter(None, (p.strip() for p in text.split(","))):
        a, dash, b = part.partition("-")
        try:
            lo, hi = int(a), int(b if dash else a)
        except ValueError:
            raise ValueError(f"--seeds: {part!r} is not a seed or a range a-b") from None
        if not 0 <= lo <= hi:
            raise ValueError(f"--seeds: {part!r} is not a seed >= 0 or a range a-b with a <= b")
        if len(seeds) + hi - lo + 1 > MAX_SEEDS:
            raise ValueError(f"--seeds: {text!r} names more than {MAX_SEEDS} seeds")
        seeds.extend(range(lo, hi + 1))
    if not seeds:
        raise ValueError("--seeds: no seeds given")
    return seeds


def _progress() -> Any:
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        transient=False,
        console=Console(stderr=True),  # stdout is for results (--json)
    )


@drive_app.command()
def collect(
    out: Annotated[Path, typer.Option("--out", help="Dataset folder (Udacity layout).")],
    episodes: Annotated[int, typer.Option(min=1, help="Expert episodes (tracks).")] = 10,
    seed_start: Annotated[int, typer.Option(help="First track seed.")] = 0,
    camera: Annotated[str, typer.Option(help="front | topdown")] = "front",
    record_every: Annotated[int, typer.Option(min=1, help="Record every N steps (50 Hz).")] = 4,
    noise: Annotated[
        float, typer.Option(min=0.0, callback=finite, help="Std of the steering noise.")
    ] = 0.25,
    max_steps: Annotated[int, typer.Option(min=10, help="Steps per episode.")] = 1200,
) -> None:
    """Record expert demonstrations (driving_log.csv + IMG/); reruns resume."""
    with _user_errors():
        from uvnav.driving.collect import CollectParams
        from uvnav.driving.collect import collect as run_collect
        from uvnav.driving.sim import DrivingSim

        if camera not in ("front", "topdown"):
            raise ValueError(f"--camera: {camera!r} (must be 'front' or 'topdown')")
        params = CollectParams(record_every=record_every, noise_sigma=noise, max_steps=max_steps)
        sim = DrivingSim(camera=camera, max_steps=max_steps)  # type: ignore[arg-type]
        seeds = range(seed_start, seed_start + episodes)
        with _progress() as prog:
            task = prog.add_task("collect", total=episodes)
            rows = run_collect(
                out,
                seeds,
                params=params,
                sim=sim,
                on_episode=lambda s, n: prog.advance(task),
            )
        sim.close()
        typer.echo(f"wrote {rows} rows ({3 * rows} images) to {out}")


@drive_app.command()
def train(
    data: Annotated[Path, typer.Argument(help="Dataset folder (driving_log.csv + IMG/).")],
    out: Annotated[Path, typer.Option("--out", help="Model file (.safetensors).")] = Path(
        "model.safetensors"
    ),
    epochs: Annotated[int, typer.Option(min=1, help="Epochs (thesis: 30).")] = 30,
    batch_size: Annotated[int, typer.Option(min=1, help="Batch size (thesis: 100).")] = 100,
    lr: Annotated[
        float, typer.Option(min=0.0, callback=finite, help="Adam learning rate (thesis: 1e-3).")
    ] = 1e-3,
    device: Annotated[str, typer.Option(help="torch device (cpu, cuda).")] = "cpu",
    threads: Annotated[int, typer.Option(min=1, max=2, help="torch CPU threads.")] = 1,
    max_per_bin: Annotated[int, typer.Option(min=0, help="Balancing threshold (0: none).")] = 200,
    bins: Annotated[int, typer.Option(min=1, help="Steering histogram bins.")] = 25,
    correction: Annotated[
        float,
        typer.Option(
            callback=unit_range,
            help="Left/right steering correction where a row has no exact side label.",
        ),
    ] = 0.2,
    exact_sides: Annotated[
        bool,
        typer.Option(
            help="Label side images with the recorded exact side labels (columns 9-10, written "
            "by 'uvnav drive collect'); --no-exact-sides: ±correction everywhere (the thesis)."
        ),
    ] = True,
    augment: Annotated[bool, typer.Option(help="Flip/brightness/zoom augmentation.")] = True,
    speed_input: Annotated[bool, typer.Option(help="Feed the speed to the network.")] = True,
    throttle_head: Annotated[bool, typer.Option(help="Learn the throttle too.")] = True,
    head: Annotated[
        str,
        typer.Option(
            help="Second output: throttle (the thesis's pedal head) or target-speed (the "
            "expert's target speed; drive it with --throttle learned-speed)."
        ),
    ] = "throttle",
    target_speed_max: Annotated[
        float | None,
        typer.Option(
            min=1.0,
            callback=finite,
            help="target-speed head: cap of the label [m/s] (the top speed).",
        ),
    ] = None,
    seed: Annotated[
        int,
        typer.Option(
            "--seed", min=0, help="Seed of the split, the initial weights and the shuffling."
        ),
    ] = 0,
) -> None:
    """Train the Chapter 6 CNN (Adam, MSE) and write the model and its loss curves."""
    with _user_errors():
        from uvnav.driving.pipeline import prepare_data, train_on
        from uvnav.learning import PilotNetConfig, TrainConfig

        second = _parse_head(head)
        _check_device(device)
        meta = _dataset_meta(data)
        size = (int(meta.get("height", 66)), int(meta.get("width", 200)))
        sides = meta.get("camera", "front") == "front"
        prep = prepare_data(
            data,
            correction=correction if sides else 0.0,
            n_bins=bins,
            max_per_bin=max_per_bin or None,
            seed=seed,
            size=size,
            sides=sides,
            exact_sides=exact_sides,
        )
        net = PilotNetConfig(
            height=size[0],
            width=size[1],
            n_outputs=2 if throttle_head else 1,
            extra_inputs=1 if speed_input else 0,
            second_output=second,
            target_speed_max=target_speed_max or PilotNetConfig.target_speed_max,
        )
        cfg = TrainConfig(
            epochs=epochs,
            batch_size=batch_size,
            lr=lr,
            augment=augment,
            seed=seed,
            threads=threads,
            device=device,
        )
        with _progress() as prog:
            task = prog.add_task("train", total=epochs)

            def on_epoch(e: int, tl: float, vl: float) -> None:
                prog.update(task, advance=1, description=f"train {tl:.4f} val {vl:.4f}")

            _, record = train_on(prep, out, net=net, config=cfg, on_epoch=on_epoch)
        extra = (
            f", target speed RMSE {record['val_target_speed_rmse'][-1]:.2f} m/s"
            if record["val_target_speed_rmse"]
            else ""
        )
        typer.echo(
            f"{prep.n_frames} frames, {prep.info['n_balanced']} after balancing, "
            f"train {prep.info['n_train']} / val {prep.info['n_val']}; final val MSE "
            f"{record['val_loss'][-1]:.4f} (steering {record['val_steering_mse'][-1]:.4f}, "
            f"second output {record['val_throttle_mse'][-1]:.4f}{extra})"
        )
        by_cam = record["val_steering_mse_by_camera"]
        if by_cam:
            typer.echo(
                "validation steering MSE by camera: "
                + ", ".join(f"{k} {v:.4f}" for k, v in by_cam.items())
                + f" (side labels: {prep.info['side_labels']})"
            )
        typer.echo(f"wrote {out}")


@drive_app.command("speed-head")
def speed_head(
    model: Annotated[Path, typer.Argument(help="Trained throttle-head model (.safetensors).")],
    data: Annotated[Path, typer.Argument(help="Its dataset (with the target_speed column).")],
    out: Annotated[Path, typer.Option("--out", help="Output model (.safetensors).")] = Path(
        "model-speed.safetensors"
    ),
    target_speed_max: Annotated[
        float | None,
        typer.Option(min=1.0, callback=finite, help="Cap of the target-speed label [m/s]."),
    ] = None,
    seed: Annotated[
        int, typer.Option("--seed", min=0, help="Seed of the split (as in training).")
    ] = 0,
) -> None:
    """Replace the throttle output by a linear target-speed readout (steering unchanged)."""
    with _user_errors():
        from uvnav.driving.pipeline import fit_target_speed_readout, prepare_data
        from uvnav.learning.checkpoint import load_checkpoint, save_checkpoint

        net, _ = load_checkpoint(model)
        prep = prepare_data(data, seed=seed, size=(net.config.height, net.config.width))
        new, record = fit_target_speed_readout(net, prep, target_speed_max=target_speed_max)
        save_checkpoint(new, out, record={**record, "source": str(model)})
        typer.echo(
            f"target speed readout: val RMSE {record['val_target_speed_rmse'][0]:.2f} m/s "
            f"(R² {record['val_target_speed_r2']:.3f}), steering val MSE "
            f"{record['val_steering_mse'][0]:.4f}; wrote {out} "
            "(drive it with --throttle learned-speed)"
        )


def _check_device(device: str) -> None:
    """Refuse a ``--device`` torch does not know, or one this machine does not have."""
    import torch

    try:
        dev = torch.device(device)
    except (RuntimeError, TypeError, ValueError) as exc:
        raise ValueError(f"--device: {device!r} is not a torch device ({exc})") from None
    if dev.type == "cpu":
        return
    if dev.type == "cuda":
        if not torch.cuda.is_available():
            raise ValueError(f"--device: {device!r}: CUDA is not available on this machine")
        if dev.index is not None and dev.index >= torch.cuda.device_count():
            raise ValueError(
                f"--device: {device!r}: this machine has {torch.cuda.device_count()} CUDA device(s)"
            )
        return
    if dev.type == "mps" and torch.backends.mps.is_available():
        return
    raise ValueError(f"--device: {device!r} is not available (use cpu or cuda)")


def _parse_head(head: str) -> str:
    """``--head`` value → ``PilotNetConfig.second_output``."""
    heads = {"throttle": "throttle", "target-speed": "target_speed", "target_speed": "target_speed"}
    if head not in heads:
        raise ValueError(f"--head: {head!r} (must be throttle or target-speed)")
    return heads[head]


def _dataset_meta(data: Path) -> dict[str, Any]:
    from uvnav.driving.collect import dataset_meta

    return dataset_meta(data) or {"camera": "front"}


def _load_policy(
    model_path: Path,
    throttle: str,
    set_speed: float,
    speed_factor: float = 1.0,
    max_speed: float | None = None,
    backend: str = "torch",
) -> tuple[Any, Any, dict[str, Any]]:
    """The model's policy and the simulator settings it was trained for: ``(policy, on_reset,
    DrivingSim keyword arguments)`` — the camera, and the front camera's field of view from the
    training record (90° for checkpoints older than that record)."""
    from uvnav.driving.camera import CameraSpec
    from uvnav.driving.collect import LEGACY_FOV_DEG
    from uvnav.driving.pipeline import THROTTLE_MODES, cnn_policy
    from uvnav.learning.checkpoint import load_checkpoint

    if throttle not in THROTTLE_MODES:
        raise ValueError(f"--throttle: {throttle!r} (must be {', '.join(THROTTLE_MODES)} or both)")
    model, header = load_checkpoint(model_path)
    sim_kw: dict[str, Any] = {
        "camera": "topdown" if (model.config.height, model.config.width) == (96, 96) else "front"
    }
    if sim_kw["camera"] == "front":
        fov = header.get("record", {}).get("camera_fov_deg", LEGACY_FOV_DEG)
        if fov is not None:
            sim_kw["camera_spec"] = CameraSpec(fov=math.radians(float(fov)))
    policy, on_reset = cnn_policy(
        model,
        throttle=throttle,  # type: ignore[arg-type]
        set_speed=set_speed,
        speed_factor=speed_factor,
        max_speed=max_speed,
        backend=backend,
    )
    return policy, on_reset, sim_kw


@drive_app.command()
def evaluate(
    model: Annotated[Path, typer.Argument(help="Model file (.safetensors).")],
    seeds: Annotated[str, typer.Option(help="Held-out track seeds, e.g. 1000-1019.")] = "1000-1019",
    throttle: Annotated[
        str,
        typer.Option(
            help="learned (throttle head) | learned-speed (target-speed head tracked by the "
            "expert's P law) | pi | both (the model's learned mode and pi)"
        ),
    ] = "both",
    set_speed: Annotated[
        float, typer.Option(callback=finite, help="PI target speed [m/s].")
    ] = 35.0,
    speed_factor: Annotated[
        float,
        typer.Option(
            callback=finite, help="learned-speed: track this fraction of the predicted speed."
        ),
    ] = 1.0,
    max_speed: Annotated[
        float | None, typer.Option(callback=finite, help="learned-speed: speed limiter [m/s].")
    ] = None,
    max_steps: Annotated[int, typer.Option(min=10, help="Steps per episode.")] = 2000,
    expert: Annotated[bool, typer.Option(help="Also drive the (oracle) expert.")] = True,
    backend: Annotated[
        str, typer.Option(help="Inference: torch, or onnxruntime (checked against torch).")
    ] = "torch",
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object instead of the table.")
    ] = False,
) -> None:
    """Closed loop on held-out tracks: return, tiles %, laps, centre distance, autonomy."""
    with _user_errors():
        from uvnav.driving.evaluate import expert_policy, summarize
        from uvnav.driving.pipeline import default_learned_mode
        from uvnav.driving.pipeline import evaluate as run_eval
        from uvnav.driving.sim import DrivingSim
        from uvnav.learning.checkpoint import load_checkpoint

        seed_list = parse_seeds(seeds)
        if backend not in ("torch", "onnxruntime"):
            raise ValueError(f"--backend: {backend!r} (must be torch or onnxruntime)")
        modes: list[str]
        if throttle == "both":
            net, _ = load_checkpoint(model)
            modes = [default_learned_mode(net), "pi"]
        else:
            modes = [throttle]
        rows: dict[str, dict[str, float]] = {}
        with _progress() as prog:
            for mode in modes:
                policy, on_reset, sim_kw = _load_policy(
                    model, mode, set_speed, speed_factor, max_speed, backend
                )
                sim = DrivingSim(**sim_kw, max_steps=max_steps)
                task = prog.add_task(f"cnn + {mode} throttle", total=len(seed_list))
                res = run_eval(
                    policy,
                    seed_list,
                    on_reset=on_reset,
                    max_steps=max_steps,
                    sim=sim,
                    on_episode=lambda r, t=task: prog.advance(t),  # type: ignore[misc]
                )
                sim.close()
                rows[f"cnn-{mode}"] = summarize(res)
            if expert:
                sim = DrivingSim(max_steps=max_steps)
                task = prog.add_task("expert (oracle)", total=len(seed_list))
                res = run_eval(
                    expert_policy(sim),
                    seed_list,
                    max_steps=max_steps,
                    sim=sim,
                    on_episode=lambda r: prog.advance(task),
                )
                sim.close()
                rows["expert"] = summarize(res)
        if "expert" in rows:
            for row in rows.values():
                row["return_vs_expert"] = row["return"] / rows["expert"]["return"]
        _print_rows(rows, as_json)


#: closed-loop columns: (key, header, format); headers short enough for 80 columns
_LOOP_COLUMNS = (
    ("n", "n", "{:.0f}"),
    ("return", "return", "{:.1f}"),
    ("return_vs_expert", "return\n/ expert", "{:.2f}"),
    ("tiles_pct", "tiles\n[%]", "{:.1f}"),
    ("laps", "laps", "{:.2f}"),
    ("mean_centre_distance", "centre\ndist.", "{:.2f}"),
    ("off_track_events", "off\ntrack", "{:.1f}"),
    ("autonomy", "auto-\nnomy", "{:.3f}"),
    ("mean_speed", "speed", "{:.1f}"),
)


def loop_cells(row: dict[str, float]) -> list[str]:
    """One driver's closed-loop cells (:data:`_LOOP_COLUMNS`; ``—`` where it has no value).

    >>> loop_cells({"n": 20.0, "return": 812.345, "autonomy": 0.9876})[:3]
    ['20', '812.3', '—']
    """
    return [fmt.format(row[key]) if key in row else "—" for key, _, fmt in _LOOP_COLUMNS]


def _print_rows(rows: dict[str, dict[str, float]], as_json: bool) -> None:
    if as_json:
        typer.echo(dumps(rows, indent=2))  # strict JSON: a missing value is null, never NaN
        return
    from uvnav.cli.common import compact_table, console

    table = compact_table(
        "closed loop (means over seeds)",
        "centre dist.: mean distance to the centreline [m]; off track [events]; speed [m/s]",
    )
    table.add_column("driver", overflow="fold")
    for _, head, _ in _LOOP_COLUMNS:
        table.add_column(head, justify="right", no_wrap=True)
    for name, row in rows.items():
        table.add_row(name, *loop_cells(row))
    console().print(table)


@drive_app.command()
def play(
    model: Annotated[Path, typer.Argument(help="Model file (.safetensors).")],
    out: Annotated[Path, typer.Option("--out", help="Output .gif or .mp4.")] = Path("drive.gif"),
    seed: Annotated[
        int, typer.Option("--seed", min=0, help="Episode seed (the track driven).")
    ] = 1000,
    steps: Annotated[int, typer.Option(min=1, help="Steps to drive.")] = 500,
    every: Annotated[int, typer.Option(min=1, help="Keep every N-th frame.")] = 5,
    throttle: Annotated[str, typer.Option(help="learned | learned-speed | pi")] = "learned",
) -> None:
    """Drive one track and write the frames with predicted vs expert steering."""
    with _user_errors():
        from uvnav.driving.expert import PurePursuitExpert
        from uvnav.driving.sim import DrivingSim
        from uvnav.viz.figures_ch6 import write_drive_video

        if out.suffix.lower() not in (".gif", ".mp4"):
            raise ValueError(f"--out: {out} (must end in .gif or .mp4)")
        policy, on_reset, sim_kw = _load_policy(model, throttle, 35.0)
        sim = DrivingSim(**sim_kw, max_steps=steps)
        frame, tel = sim.reset(seed)
        if on_reset:
            on_reset()
        assert sim.geometry is not None
        exp = PurePursuitExpert(sim.geometry)
        frames, pred, ref = [], [], []
        for k in range(steps):
            steer, thr = policy(frame, tel)
            if k % every == 0:
                frames.append(frame)
                pred.append(steer)
                ref.append(exp.act(tel)[0])
            st = sim.step_on_track(steer, thr)
            frame, tel = st.frame, st.telemetry
            if st.terminated or st.truncated:
                break
        sim.close()
        write_drive_video(frames, pred, ref, out, fps=max(1, 50 // every))
        typer.echo(f"wrote {out} ({len(frames)} frames)")


@drive_app.command()
def dagger(
    data: Annotated[Path, typer.Argument(help="Dataset folder (rows are appended).")],
    model: Annotated[Path, typer.Argument(help="Starting model (.safetensors).")],
    rounds: Annotated[int, typer.Option(min=1, help="DAgger rounds.")] = 1,
    episodes: Annotated[int, typer.Option(min=1, help="Training tracks driven per round.")] = 6,
    epochs: Annotated[int, typer.Option(min=1, help="Training epochs per round.")] = 5,
    first_seed: Annotated[int, typer.Option(help="First training track of round 1.")] = 600,
    seeds: Annotated[
        str, typer.Option(help="Held-out seeds evaluated after each round.")
    ] = "1000-1019",
    throttle: Annotated[
        str,
        typer.Option(help="The learner's throttle while driving: pi, learned or learned-speed."),
    ] = "pi",
    set_speed: Annotated[
        float, typer.Option(callback=finite, help="PI target speed [m/s].")
    ] = 35.0,
    out_dir: Annotated[Path, typer.Option("--out-dir", help="Folder of the round models.")] = Path(
        "dagger"
    ),
    baseline: Annotated[
        bool, typer.Option(help="Also evaluate the starting model (round 0).")
    ] = True,
) -> None:
    """DAgger: the CNN drives, the expert labels, retrain; prints closed loop per round."""
    with _user_errors():
        from uvnav.driving.evaluate import summarize
        from uvnav.driving.pipeline import THROTTLE_MODES, cnn_policy, run_dagger
        from uvnav.driving.pipeline import evaluate as run_eval
        from uvnav.learning.checkpoint import load_checkpoint

        if throttle not in THROTTLE_MODES:
            raise ValueError(f"--throttle: {throttle!r} (must be {', '.join(THROTTLE_MODES)})")
        seed_list = parse_seeds(seeds)
        net, _ = load_checkpoint(model)
        rows: dict[str, dict[str, float]] = {}
        if baseline:
            policy, on_reset = cnn_policy(net, throttle=throttle, set_speed=set_speed)  # type: ignore[arg-type]
            rows["round-0"] = summarize(run_eval(policy, seed_list, on_reset=on_reset))
        _, done = run_dagger(
            net,
            data,
            out_dir,
            rounds=rounds,
            episodes=episodes,
            epochs=epochs,
            eval_seeds=seed_list,
            first_seed=first_seed,
            throttle=throttle,  # type: ignore[arg-type]
            set_speed=set_speed,
            progress=lambda s: typer.echo(s, err=True),
        )
        for d in done:
            rows[f"round-{d.round_id}"] = {**d.summary, "rows_added": float(d.rows)}
            typer.echo(f"round {d.round_id}: +{d.rows} rows, wrote {d.model_path}")
        _print_rows(rows, False)


@drive_app.command()
def reproduce(
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("results/ch6"),
    full: Annotated[bool, typer.Option("--full", help="Thesis-size run (hours on CPU).")] = False,
    episodes: Annotated[int | None, typer.Option(help="Override: expert episodes.")] = None,
    epochs: Annotated[int | None, typer.Option(help="Override: epochs.")] = None,
    seeds: Annotated[str | None, typer.Option(help="Override: held-out seeds.")] = None,
    max_steps: Annotated[int | None, typer.Option(help="Override: closed-loop steps.")] = None,
    dagger_rounds: Annotated[
        int | None,
        typer.Option(min=0, help="Override: DAgger rounds (default 1 with --full, else 0)."),
    ] = None,
    head: Annotated[
        str,
        typer.Option(
            help="Second output: throttle (thesis; closed loop 'learned') or target-speed "
            "(closed loop 'learned-speed')."
        ),
    ] = "throttle",
    readout: Annotated[
        bool,
        typer.Option(help="Thesis head: also fit the target-speed readout (cnn-learned-speed)."),
    ] = True,
    fresh: Annotated[
        bool, typer.Option("--fresh", help="Remake every stage (the expert recording too).")
    ] = False,
    threads: Annotated[int, typer.Option(min=1, max=2, help="torch CPU threads for training.")] = 1,
    noise: Annotated[
        float | None,
        typer.Option(
            min=0.0,
            callback=finite,
            help="Std of the recording's steering noise (default 0.25).",
        ),
    ] = None,
) -> None:
    """Chapter 6 end to end: data, Figs. 6.1/6.4–6.8, training, closed-loop table.

    The chain: the thesis's network (learned pedal head and PI rows), the target-speed readout
    (learned-speed row), DAgger rounds with the learned-speed throttle (one in --full), the
    expert.  Resumable: finished stages (out/stages/) are skipped on a rerun.
    """
    with _user_errors():
        from rich.console import Console
        from rich.table import Table

        from uvnav.experiments.ch6 import reproduce_ch6
        from uvnav.viz.figures_ch6 import render_ch6

        con = Console(stderr=True)
        summary = reproduce_ch6(
            out,
            full=full,
            episodes=episodes,
            epochs=epochs,
            eval_seeds=parse_seeds(seeds) if seeds else None,
            max_steps=max_steps,
            dagger_rounds=dagger_rounds,
            head=_parse_head(head),
            readout=readout,
            fresh=fresh,
            threads=threads,
            noise_sigma=noise,
            progress=lambda s: con.print(f"[dim]… {s}[/dim]"),
        )
        figures = render_ch6(summary, out / "figures")
        table = Table(title="Chapter 6: thesis reported vs uvnav measured")
        for col in ("quantity", "thesis", "measured", "note"):
            table.add_column(col)
        for row in summary.table:
            table.add_row(*(row[c] for c in ("quantity", "thesis", "measured", "note")))
        Console().print(table)
        _print_rows(summary.closed_loop, False)
        typer.echo(f"wrote {len(figures)} figures in {out / 'figures'} and {out / 'ch6.json'}")
