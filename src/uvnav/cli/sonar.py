"""``uvnav sonar``: the Chapter 5 sonar array, its data and its BPNN (thesis Ch. 5, Figs. 5.4-5.8).

Commands (thin: they parse, call the library, print):

* ``dataset`` — sample R(t) with true-geometry targets (:mod:`uvnav.sensors.sonar_dataset`) into
  an ``.npz`` file (plain arrays; read back with ``allow_pickle=False``);
* ``train`` — train the BPNN (:mod:`uvnav.learning.bpnn`) with a random train/validation/test
  division and early stopping, write a safetensors checkpoint + JSON; ``--variant`` picks the
  network (``plain``: the thesis's; ``residual``; ``residual-huber``) and ``--targets`` what it
  learns (``geometry``: the true nearest distance and sensor; ``readings``: min/argmin of its own
  inputs, the thesis's set-up) — every variant the Chapter 5 report shows;
* ``evaluate`` — errors target - output of a checkpoint (any variant, on the targets it was
  trained for) on a dataset, beside the min/argmin baseline and the thesis's ranges.

A closed-loop episode is ``uvnav simulate`` (``--param locator=network --param model=CKPT`` for
the trained network).  The chapter's reproduction (BPNN experiment + closed-loop campaigns) is
``uvnav reproduce ch5``.

Bad input (missing or malformed files, bad options) prints ONE line ``error: ...`` naming the
file and the problem, and exits with status 2.
"""

from __future__ import annotations

import zipfile
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from uvnav.cli.checks import dumps, finite
from uvnav.cli.errors import CliError, uvnav_typer

#: the largest dataset ``sonar dataset`` draws (each sample is one placed scene and its R(t))
MAX_SAMPLES = 1_000_000

sonar_app = uvnav_typer(
    help="Chapter 5: nine-sonar array data and the BPNN locator (dataset, train, evaluate).",
)


def _progress() -> Any:
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    return Progress(
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        transient=True,
        console=Console(stderr=True),  # stdout is for results (--json)
    )


def _load_dataset(path: Path) -> Any:
    from uvnav.sensors.sonar_array import N_SONARS
    from uvnav.sensors.sonar_dataset import SonarDataset
    from uvnav.validation import load_npz

    if not path.is_file():
        raise CliError(f"{path}: dataset file not found")
    try:
        arrays = load_npz(path, N_SONARS * MAX_SAMPLES)
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as exc:
        raise CliError(
            f"{path}: not a uvnav sonar dataset (.npz): {exc or type(exc).__name__}"
        ) from None
    try:
        return SonarDataset.from_arrays(arrays)
    except ValueError as exc:
        raise CliError(f"{path}: {exc}") from None


@sonar_app.command("dataset")
def dataset_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output .npz file.")] = Path("sonar.npz"),
    samples: Annotated[
        int,
        typer.Option("--samples", "-n", min=1, max=MAX_SAMPLES, help="Samples (the thesis: 150)."),
    ] = 150,
    seed: Annotated[int, typer.Option("--seed", min=0, help="Seed of the sampling.")] = 0,
    noise: Annotated[
        float, typer.Option(min=0.0, callback=finite, help="Sonar range noise std [m].")
    ] = 0.0,
    dropout: Annotated[
        float, typer.Option(min=0.0, max=1.0, callback=finite, help="Echo dropout rate.")
    ] = 0.0,
    subdivisions: Annotated[
        int, typer.Option(min=1, max=4, help="Icosphere level of the obstacle meshes.")
    ] = 2,
) -> None:
    """Sample sonar readings with true nearest distance and sensor targets."""
    from uvnav.sensors.sonar_array import SonarArray
    from uvnav.sensors.sonar_dataset import sample_sonar_dataset

    array = SonarArray(noise_std=noise, dropout=dropout)
    with _progress() as prog:
        task = prog.add_task("sampling", total=samples)
        ds = sample_sonar_dataset(
            samples,
            np.random.default_rng(seed),
            array=array,
            subdivisions=subdivisions,
            on_sample=lambda k: prog.update(task, completed=k),
        )
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(out, **ds.arrays())  # type: ignore[arg-type]
    gap = ds.baseline_distance - ds.target_distance
    right = float(np.mean(ds.baseline_index == ds.target_index))
    typer.echo(
        f"wrote {out}: {len(ds)} samples; min/argmin baseline distance error "
        f"[{-gap.max():.4f}, {-gap.min():.4f}] m, index right {right:.1%}"
    )


@sonar_app.command("train")
def train_cmd(
    data: Annotated[Path, typer.Argument(help="Dataset .npz from 'uvnav sonar dataset'.")],
    out: Annotated[Path, typer.Option("--out", help="Checkpoint path (stem).")] = Path("bpnn"),
    hidden: Annotated[str, typer.Option(help="Hidden layer sizes, e.g. '10' or '20,10'.")] = "10",
    optimizer: Annotated[str, typer.Option(help="lbfgs (default) or adam.")] = "lbfgs",
    seed: Annotated[
        int, typer.Option("--seed", min=0, help="Seed of the division and the initial weights.")
    ] = 0,
    max_epochs: Annotated[int, typer.Option(min=1, help="Largest number of epochs.")] = 1000,
    variant: Annotated[
        str, typer.Option(help="Network: plain (the thesis's), residual or residual-huber.")
    ] = "plain",
    targets: Annotated[
        str,
        typer.Option(
            help="What it learns: geometry (true nearest distance and sensor) or readings "
            "(min/argmin of its inputs, the thesis's set-up)."
        ),
    ] = "geometry",
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object instead of the table.")
    ] = False,
) -> None:
    """Train the BPNN with a random division and early stopping; write a safe checkpoint."""
    from uvnav.learning.bpnn import (
        VARIANTS,
        error_table,
        save_checkpoint,
        train_bpnn,
        variant_config,
    )
    from uvnav.sensors.sonar_dataset import TARGET_KINDS

    if variant not in VARIANTS:
        raise CliError(f"--variant: {variant!r} (must be one of {', '.join(VARIANTS)})")
    if targets not in TARGET_KINDS:
        raise CliError(f"--targets: {targets!r} (must be one of {', '.join(TARGET_KINDS)})")
    try:
        sizes = tuple(int(h) for h in hidden.split(","))
    except ValueError as exc:
        raise CliError(f"--hidden: {exc}") from None
    try:
        cfg = variant_config(variant, hidden=sizes, optimizer=optimizer, max_epochs=max_epochs)
    except ValueError as exc:
        raise CliError(f"--hidden/--optimizer: {exc}") from None
    ds = _load_dataset(data)
    y = ds.targets(targets)
    try:
        model = train_bpnn(
            ds.inputs,
            y,
            np.random.default_rng(seed),
            cfg,
            offset=ds.baseline(),
            target_kind=targets,
        )
    except ValueError as exc:
        raise CliError(f"{data}: {exc}") from None
    st, js = save_checkpoint(model, out)
    test = model.split["test"]
    pred = model.predict(ds.inputs[test], ds.baseline()[test])
    table = error_table(pred, y[test], ds.baseline()[test])
    if as_json:
        typer.echo(
            dumps(
                {
                    "variant": model.variant,
                    "targets": model.target_kind,
                    "test": table,
                    "best_epoch": model.best_epoch,
                    "stop_reason": model.stop_reason,
                }
            )
        )
    else:
        _print_table(table, len(ds), f"test group ({len(test)} samples), {_what(model)}")
        typer.echo(f"stopped: {model.stop_reason} (best epoch {model.best_epoch})")
    note = worse_than_baseline(table, model.variant)
    if note:
        typer.echo(note, err=True)
    typer.echo(f"wrote {st} and {js}", err=as_json)  # --json: stdout holds the JSON alone


def worse_than_baseline(table: dict[str, Any], variant: str) -> str | None:
    """A one-line note when the network locates worse than the min/argmin of its own inputs on
    the test group (its distance MAE above the baseline's), with what to try; ``None``
    otherwise.

    >>> t = {"network": {"distance": {"mae": 0.41}}, "baseline": {"distance": {"mae": 0.013}}}
    >>> worse_than_baseline(t, "plain")[:60]
    "note: the network's distance MAE on its test group, 0.41 m, "
    >>> worse_than_baseline({**t, "network": {"distance": {"mae": 0.01}}}, "plain") is None
    True
    """
    net = table.get("network", {}).get("distance", {}).get("mae")
    base = table.get("baseline", {}).get("distance", {}).get("mae")
    if net is None or base is None or not net > base:
        return None
    hint = (
        "try --variant residual-huber (a correction to the baseline) or more samples"
        if variant == "plain"
        else "try more samples or another --seed"
    )
    return (
        f"note: the network's distance MAE on its test group, {net:.2g} m, is worse than the "
        f"min/argmin baseline's, {base:.2g} m: {hint}"
    )


@sonar_app.command("evaluate")
def evaluate_cmd(
    model_path: Annotated[Path, typer.Argument(help="Checkpoint (.safetensors, .json or stem).")],
    data: Annotated[Path, typer.Argument(help="Dataset .npz to evaluate on.")],
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object instead of the table.")
    ] = False,
) -> None:
    """Errors (target - output) of a trained network and of the min/argmin baseline."""
    from uvnav.learning.bpnn import CheckpointError, error_table, load_checkpoint

    try:
        model = load_checkpoint(model_path)
    except CheckpointError as exc:
        raise CliError(str(exc)) from None
    ds = _load_dataset(data)
    if ds.inputs.shape[1] != model.n_inputs:
        raise CliError(
            f"{data}: {ds.inputs.shape[1]} inputs per sample, the model takes {model.n_inputs}"
        )
    y = ds.targets(model.target_kind)
    table = error_table(model.predict(ds.inputs, ds.baseline()), y, ds.baseline())
    if as_json:
        typer.echo(dumps({"variant": model.variant, "targets": model.target_kind, **table}))
    else:
        _print_table(table, None, f"{data} ({len(ds)} samples), {_what(model)}")


def _what(model: Any) -> str:
    """``"variant plain, targets readings"``: what a network is, for table titles."""
    return f"variant {model.variant}, targets {model.target_kind}"


def _print_table(table: dict[str, Any], n_train: int | None, title: str) -> None:
    from rich.console import Console
    from rich.table import Table

    from uvnav.learning.bpnn import THESIS_ACCEPTED, THESIS_ERROR_RANGES

    t = Table(title=f"errors target - output, {title}")
    for col in ("who", "distance range [m]", "distance MAE [m]", "index range", "index right"):
        t.add_column(col)
    for who, row in table.items():
        d, i = row["distance"], row["index"]
        t.add_row(
            who,
            f"[{d['lo']:.4g}, {d['hi']:.4g}]",
            f"{d['mae']:.4g}",
            f"[{i['lo']:.4g}, {i['hi']:.4g}]",
            f"{row['index_accuracy']:.1%}",
        )
    for n, ref in THESIS_ERROR_RANGES.items():
        if n_train is None or n_train == n:
            d, i = ref["distance"], ref["index"]
            verdict = "accepted" if THESIS_ACCEPTED[n] else "a failure"
            t.add_row(
                f"thesis ({n} samples, {verdict})", f"[{d[0]}, {d[1]}]", "", f"[{i[0]}, {i[1]}]", ""
            )
    Console().print(t)
