"""``uvnav crowd``: the learned crowd law ``crowd-ppo-v1`` (training).

* ``train`` — PPO (stable-baselines3) with an attention set encoder on CrowdNav's circle crossing,
  train-phase seeds (:mod:`uvnav.learning.crowd_policy`); writes the actor's weights
  (safetensors) and their header with the training record (JSON beside them).  The shipped
  weights are ``uvnav crowd train`` with its defaults; a trained file drives the law with
  ``--param weights=FILE``.  The run's state is saved beside the weights file every 100,000
  steps and on Ctrl-C (``NAME.ckpt.zip``); the same command with ``--resume`` continues it, and
  the checkpoint is removed once the weights are written.

Evaluation is the law's, as any law's: ``uvnav simulate crowdnav-circle:0 --controller
crowd-ppo-v1``, ``uvnav bench``, ``benchmarks/bench_crowdnav.py --law crowd-ppo-v1``.

Bad options print ONE line ``error: ...`` naming the option and exit with status 2.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from uvnav.cli.checks import dumps
from uvnav.cli.errors import EX_INTERRUPTED, CliError, uvnav_typer

crowd_app = uvnav_typer(help="The learned crowd law crowd-ppo-v1: train its PPO policy.")

#: the most environment steps one training run takes
MAX_STEPS = 100_000_000


@crowd_app.command("train")
def train_cmd(
    out: Annotated[Path, typer.Option("--out", help="Weights file (.safetensors).")] = Path(
        "crowd-ppo-v1.safetensors"
    ),
    steps: Annotated[int, typer.Option(min=1, help="PPO environment steps in all.")] = 2_000_000,
    seed: Annotated[int, typer.Option(min=0, help="Seed of PPO, its envs and the cases.")] = 0,
    n_envs: Annotated[
        int, typer.Option("--n-envs", min=1, max=64, help="Envs stepped together.")
    ] = 8,
    n_steps: Annotated[
        int, typer.Option("--n-steps", min=2, help="Steps per env per PPO update.")
    ] = 256,
    humans_start: Annotated[
        int,
        typer.Option(
            "--humans-start",
            min=0,
            max=5,
            help="Humans per scene at the start of a linear curriculum to 5 (5: none).",
        ),
    ] = 5,
    resume: Annotated[
        bool,
        typer.Option(
            "--resume", help="Continue the interrupted run whose checkpoint is beside --out."
        ),
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", help="No progress lines on stderr.")] = False,
    as_json: Annotated[
        bool,
        typer.Option(
            "--json", help="Print one JSON object (the training record) instead of the table."
        ),
    ] = False,
) -> None:
    """Train crowd-ppo-v1's policy on CrowdNav's circle crossing (train seeds); write it."""
    from uvnav.learning.crowd_policy import (
        CheckpointMismatchError,
        TrainConfig,
        export_policy,
        train_crowd_policy,
    )

    if steps > MAX_STEPS:
        raise CliError(f"--steps: {steps} is more than {MAX_STEPS}")
    if out.suffix != ".safetensors":
        raise CliError(f"--out: {out} must end in .safetensors")
    batch = min(256, n_envs * n_steps)
    cfg = TrainConfig(steps=steps, seed=seed, n_envs=n_envs, n_steps=n_steps,
                      batch_size=batch, humans_start=humans_start)  # fmt: skip

    ckpt = checkpoint_path(out)
    if ckpt.is_file() and not resume:
        raise CliError(
            f"--out: {ckpt} holds an interrupted run: --resume continues it (or delete it)"
        )

    def log(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    try:
        model, record = train_crowd_policy(cfg, log=None if quiet else log, checkpoint=ckpt)
    except CheckpointMismatchError as exc:
        raise CliError(f"--resume: {exc}") from None
    except KeyboardInterrupt:
        typer.echo(
            f"interrupted: the run's state is in {ckpt}; the same command with --resume "
            "continues it",
            err=True,
        )
        raise typer.Exit(EX_INTERRUPTED) from None
    path = export_policy(model, record, out, cfg.k)
    for done in (ckpt, ckpt.with_suffix(".json")):
        done.unlink(missing_ok=True)
    if as_json:
        typer.echo(dumps(record))
    else:
        typer.echo(
            f"{record['timesteps']} steps in {record['cpu_seconds']} s CPU "
            f"({record['wall_seconds']} s wall)"
        )
    typer.echo(f"wrote {path} and {path.with_suffix('.json')}", err=as_json)


def checkpoint_path(out: Path) -> Path:
    """Where ``uvnav crowd train --out OUT`` keeps its run's state: ``OUT`` with ``.ckpt.zip``
    for ``.safetensors``."""
    return out.with_suffix(".ckpt.zip")
