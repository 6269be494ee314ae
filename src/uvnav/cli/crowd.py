"""``uvnav crowd``: the learned crowd laws ``crowd-ppo-v*`` (training).

* ``train`` — PPO (stable-baselines3) with an attention set encoder on training seeds of the
  ``--rule`` scenes (CrowdNav's circle crossing by default; ``--rule`` again for a mix of circle
  and square crossing and the harder crowd), ``--humans`` humans per CrowdNav scene
  (:mod:`uvnav.learning.crowd_policy`), from a new policy or one given by ``--init`` (a shipped
  law's name or a weights file: fine-tuning); writes the actor's weights (safetensors) and their
  header with the training record (JSON beside them).  ``crowd-ppo-v1``'s weights are
  ``uvnav crowd train`` with its defaults; ``crowd-ppo-v2``'s record holds its command.  A
  trained file drives the law with ``--param weights=FILE``.  The record's ``command`` is the
  ``uvnav crowd train`` command that reproduces the weights.  The run's state is saved beside
  the weights file every 100,000 steps and on Ctrl-C (``NAME.ckpt.zip``); the same command with
  ``--resume`` continues it, and the checkpoint is removed once the weights are written.

Evaluation is the law's, as any law's: ``uvnav simulate crowdnav-circle:0 --controller
crowd-ppo-v2``, ``uvnav bench``, ``benchmarks/bench_crowdnav.py --law crowd-ppo-v2``.

Bad options print ONE line ``error: ...`` naming the option and exit with status 2.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from uvnav.cli.checks import dumps
from uvnav.cli.errors import EX_INTERRUPTED, CliError, uvnav_typer

if TYPE_CHECKING:
    from uvnav.learning.crowd_policy import TrainConfig

crowd_app = uvnav_typer(help="The learned crowd laws crowd-ppo-v*: train their PPO policy.")

#: the most environment steps one training run takes
MAX_STEPS = 100_000_000
#: the most humans per CrowdNav scene of training
MAX_HUMANS = 64


@crowd_app.command("train")
def train_cmd(
    out: Annotated[Path, typer.Option("--out", help="Weights file (.safetensors).")] = Path(
        "crowd-ppo.safetensors"
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
        int | None,
        typer.Option(
            "--humans-start",
            min=0,
            max=MAX_HUMANS,
            help="Humans per scene at the start of a linear curriculum to the --humans low "
            "(default: that low, no curriculum).",
        ),
    ] = None,
    humans: Annotated[
        str,
        typer.Option(
            "--humans", help="Humans per CrowdNav scene: N, or LOW-HIGH drawn per episode."
        ),
    ] = "5",
    rules: Annotated[
        list[str] | None,
        typer.Option(
            "--rule",
            help="A scene to train on: circle_crossing, square_crossing, crowd_dynamic; again "
            "for a mix (default: circle_crossing).",
        ),
    ] = None,
    init: Annotated[
        str,
        typer.Option(
            "--init", help="Start from this policy: a shipped law's name or a weights file."
        ),
    ] = "",
    learning_rate: Annotated[
        float,
        typer.Option("--learning-rate", min=1e-7, max=1.0, help="PPO's first learning rate."),
    ] = 3e-4,
    log_std_init: Annotated[
        float,
        typer.Option(
            "--log-std-init", min=-5.0, max=2.0, help="Log std of the first action noise."
        ),
    ] = 0.0,
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
    """Train a crowd-ppo policy on training seeds of crowd scenes; write it."""
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
    low, high = humans_range(humans)
    start = low if humans_start is None else humans_start
    if start > low:
        raise CliError(f"--humans-start: {start} is more than the --humans low {low}")
    cfg = TrainConfig(steps=steps, seed=seed, n_envs=n_envs, n_steps=n_steps,
                      batch_size=batch, humans_start=start, humans=(low, high),
                      rules=check_rules(rules or ["circle_crossing"]), init=init,
                      learning_rate=learning_rate, log_std_init=log_std_init)  # fmt: skip
    if init:
        check_init(init)

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
    record["command"] = train_command(cfg, out)
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


def humans_range(text: str) -> tuple[int, int]:
    """``(low, high)`` of ``--humans`` ``N`` or ``LOW-HIGH``.

    Raises:
        CliError: not such a range within 0..MAX_HUMANS (one line).
    """
    parts = text.split("-")
    try:
        low, high = int(parts[0]), int(parts[-1])
    except ValueError:
        low, high = -1, -1
    if len(parts) > 2 or not 0 <= low <= high <= MAX_HUMANS:
        raise CliError(f"--humans: {text!r} is not N or LOW-HIGH within 0..{MAX_HUMANS}")
    return low, high


def check_rules(rules: list[str]) -> tuple[str, ...]:
    """The ``--rule`` scenes, each once, in the order given.

    Raises:
        CliError: a scene not known (one line).
    """
    from uvnav.envs.crowd import RULES

    bad = next((r for r in rules if r not in RULES), None)
    if bad is not None:
        raise CliError(f"--rule: {bad!r} is not one of {', '.join(RULES)}")
    return tuple(dict.fromkeys(rules))


def check_init(init: str) -> None:
    """Raises CliError (one line) unless ``--init`` names a readable policy."""
    from uvnav.controllers.crowd_ppo import PolicyFileError, policy_file, read_policy

    try:
        read_policy(policy_file(init))
    except PolicyFileError as exc:
        raise CliError(f"--init: {exc}") from None


def train_command(cfg: TrainConfig, out: Path) -> str:
    """The ``uvnav crowd train`` command of ``cfg`` writing ``out``'s name (defaults left out)."""
    from uvnav.learning.crowd_policy import TrainConfig

    default = TrainConfig()
    words = ["uvnav crowd train", f"--out {out.name}", f"--steps {cfg.steps}"]
    for flag, value, dflt in (
        ("--seed", cfg.seed, default.seed),
        ("--n-envs", cfg.n_envs, default.n_envs),
        ("--n-steps", cfg.n_steps, default.n_steps),
        ("--learning-rate", cfg.learning_rate, default.learning_rate),
        ("--log-std-init", cfg.log_std_init, default.log_std_init),
    ):
        if value != dflt:
            words.append(f"{flag} {value:g}")
    low, high = cfg.humans
    words.append(f"--humans {low}" if low == high else f"--humans {low}-{high}")
    if cfg.humans_start != low:
        words.append(f"--humans-start {cfg.humans_start}")
    words += [f"--rule {r}" for r in cfg.rules]
    if cfg.init:
        words.append(f"--init {cfg.init}")
    return " ".join(words)


def checkpoint_path(out: Path) -> Path:
    """Where ``uvnav crowd train --out OUT`` keeps its run's state: ``OUT`` with ``.ckpt.zip``
    for ``.safetensors``."""
    return out.with_suffix(".ckpt.zip")
