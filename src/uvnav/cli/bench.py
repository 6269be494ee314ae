"""``uvnav bench CAMPAIGN``: run a campaign file into a results database, then summarise it.

Thin Typer command over :mod:`uvnav.bench` (the campaign spec, the local and Ray engines, the
store and the per-controller summary).  Each finished episode is stored at once, so an
interrupted campaign resumes with ``--resume``; errored episodes exit with status 1.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from uvnav.cli.checks import too_many_workers
from uvnav.cli.common import compact_table
from uvnav.cli.common import console as _console
from uvnav.cli.common import dumps as _dumps
from uvnav.cli.common import fmt as _fmt
from uvnav.cli.common import text as _text
from uvnav.cli.errors import CliError, one_line

_SUMMARY_HEADERS = {
    "episodes": "n",
    "errors": "err",
    "refused": "ref.",
    "success_rate": "success",
    "collision_rate": "collide",
    "min_clearance": "min\nclear.\n[m]",
    "detour_ratio": "detour\nratio",
    "time_ratio": "time\nratio",
    "decision_us_median": "decide\nµs\nmedian",
    "decision_us_p99": "decide\nµs\np99",
}


#: the summary columns a narrow terminal loses first, in order
_DROP_FIRST = ("decision_us_p99", "time_ratio", "refused", "errors", "detour_ratio")


def fit_columns(widths: dict[str, int], width: int, label: int = 12) -> list[str]:
    """The summary columns (``widths``: column -> its width) that fit a console of ``width``
    columns beside a ``label`` column, dropping :data:`_DROP_FIRST` in order until they fit.

    >>> fit_columns({"success_rate": 7, "decision_us_p99": 6, "time_ratio": 5}, 80)
    ['success_rate', 'decision_us_p99', 'time_ratio']
    >>> fit_columns({"success_rate": 7, "decision_us_p99": 6, "time_ratio": 5}, 25)
    ['success_rate']
    """
    kept = list(widths)

    def need() -> int:
        return label + sum(widths[c] + 2 for c in kept)

    for col in _DROP_FIRST:
        if need() <= width:
            break
        if col in kept:
            kept.remove(col)
    return kept


def _summary_cell(col: str, value: Any) -> str:
    if value is None:
        return "-"
    if col.endswith("_rate"):
        return f"{100.0 * float(value):.1f}%"
    if col in ("min_clearance", "detour_ratio", "time_ratio"):
        return f"{float(value):.3f}"
    if col.startswith("decision_us"):
        return f"{float(value):.0f}"
    return _fmt(value)


def bench_cmd(
    campaign: Annotated[Path, typer.Argument(help="Campaign YAML file (scenarios × controllers).")],
    engine: Annotated[
        str, typer.Option(help="local (process pool) or ray (Ray tasks; extra uvnav[bench]).")
    ] = "local",
    workers: Annotated[
        int | None, typer.Option(min=1, help="Worker processes / Ray CPUs (default: all CPUs).")
    ] = None,
    db: Annotated[Path, typer.Option(help="Results database (SQLite).")] = Path(
        "results/bench.sqlite"
    ),
    resume: Annotated[
        bool, typer.Option("--resume", help="Continue a campaign of the same name in --db.")
    ] = False,
    address: Annotated[
        str | None,
        typer.Option(
            help="Ray cluster to run on (--engine ray): auto, HOST:PORT or ray://HOST:PORT; "
            "default $RAY_ADDRESS, else a local Ray instance.",
        ),
    ] = None,
    retry_errors: Annotated[
        bool, typer.Option("--retry-errors", help="With --resume: run 'error' episodes again.")
    ] = False,
    json_out: Annotated[
        bool,
        typer.Option(
            "--json", help="Print one JSON object (the run and the summary) instead of the table."
        ),
    ] = False,
    failures: Annotated[
        bool,
        typer.Option(
            "--failures",
            help="Also list every episode that did not succeed: seed, cause (who closed the "
            "gap at a collision, or timeout / refused / error) and the uvnav simulate command "
            "that reruns it.  With --resume on a finished campaign: only the listing.",
        ),
    ] = False,
    mcap_dir: Annotated[
        Path | None,
        typer.Option(
            "--mcap-dir",
            help="Also write each episode this invocation runs (2D scenes) into this folder "
            "(created if missing), one MCAP file of ROS 2 messages each, named "
            "LABEL__CONTROLLER__SEED.mcap; episodes already stored and skipped get none.  "
            "Needs the 'ros' extra.",
        ),
    ] = None,
) -> None:
    """Run a benchmark campaign into a results database, then print a per-controller summary.

    Each finished episode is stored at once (one transaction), so an interrupted campaign resumes
    with --resume and never duplicates an episode.
    """
    import os
    import time
    from contextlib import ExitStack

    from uvnav.bench.campaign import ENGINES
    from uvnav.bench.ray_engine import (
        ClusterConnectionError,
        EngineUnavailableError,
        cluster_session,
        import_ray,
    )
    from uvnav.bench.spec import load_campaign, run_campaign_spec
    from uvnav.bench.store import ResultsStore, StoreInUseError
    from uvnav.bench.summary import SUMMARY_COLUMNS, controller_summary, failure_rows

    if engine not in ENGINES:
        raise CliError(f"--engine {engine!r}: expected one of {', '.join(ENGINES)}")
    if address is not None and engine != "ray":
        raise CliError("--address needs --engine ray")
    spec = load_campaign(campaign)
    session = ExitStack()  # the Ray cluster's connection, when one is given
    if engine == "ray":
        try:
            import_ray()  # before the database is created
        except EngineUnavailableError as exc:
            raise CliError(str(exc), code=1) from None
        cluster = address or os.environ.get("RAY_ADDRESS") or None
        if cluster is not None:
            try:  # fails in seconds, before the database is created; held for the run
                session.enter_context(cluster_session(cluster))
            except ClusterConnectionError as exc:
                raise CliError(f"--address: {exc}") from None
    probe_factory = _mcap_folder(mcap_dir) if mcap_dir is not None else None
    n_workers = workers or os.cpu_count() or 1
    too_many = too_many_workers(n_workers) if engine == "local" else None  # Ray: a cluster's
    if too_many is not None:
        raise CliError(f"--workers: {too_many} for --engine local")
    with session, ResultsStore(db) as store:  # Ray's connection ends before the summary
        if resume:
            before = next((c for c in store.campaigns() if c["name"] == spec.name), None)
            if before is not None and before["config"] != spec.config():
                typer.echo(
                    f"warning: {campaign} changed since campaign {spec.name!r} was created; "
                    "stored episodes are kept, new keys are run",
                    err=True,
                )
        tic = time.perf_counter()
        try:
            result = run_campaign_spec(
                store,
                spec,
                resume=resume,
                engine=engine,
                workers=n_workers,
                address=address,
                progress=not json_out,
                retry_errors=retry_errors,
                probe_factory=probe_factory,
            )
        except EngineUnavailableError as exc:
            raise CliError(str(exc), code=1) from None
        except ClusterConnectionError as exc:
            raise CliError(f"--address: {exc}") from None
        except StoreInUseError as exc:
            raise CliError(str(exc)) from None
        except KeyboardInterrupt:
            typer.echo(
                f"interrupted: {store.count(spec.name)} episode(s) of {spec.name!r} are stored in "
                f"{db}; run again with --resume to finish",
                err=True,
            )
            raise typer.Exit(130) from None
        elapsed = time.perf_counter() - tic
        rows = controller_summary(store, spec.name)
        failed = failure_rows(store, spec.name, beyond=spec.beyond_assumptions) if failures else []
        first_error = _first_error(store, spec.name) if result.errors else None
    rate = result.ran / elapsed if result.ran and elapsed > 0 else None
    if json_out:
        record = {
            "campaign": spec.name,
            "db": str(db),
            "engine": engine,
            "workers": n_workers,
            "total": result.total,
            "ran": result.ran,
            "skipped": result.skipped,
            "errors": result.errors,
            "wall_time": elapsed,
            "episodes_per_s": rate,
            "controllers": rows,
            "first_error": first_error,
        }
        if failures:
            record["failures"] = failed
        typer.echo(_dumps(record))
        _fail_on_errors(result.errors, first_error)
        return
    con = _console()
    numeric = [c for c in SUMMARY_COLUMNS if c in _SUMMARY_HEADERS]
    cells = [[_summary_cell(col, row[col]) for col in numeric] for row in rows]
    widths = {
        col: max(
            max((len(r[i]) for r in cells), default=1),
            *(len(w) for w in _SUMMARY_HEADERS[col].split("\n")),
        )
        for i, col in enumerate(numeric)
    }
    kept = fit_columns(widths, con.width)
    dropped = [_SUMMARY_HEADERS[c].replace("\n", " ") for c in numeric if c not in kept]
    caption = f"not shown at this width: {', '.join(dropped)} (--json has all)"
    table = compact_table(
        f"campaign {spec.name} ({result.total} episodes)", caption if dropped else None
    )
    table.add_column("controller\nparams", overflow="fold", ratio=1, min_width=12)
    for col in kept:
        table.add_column(
            _SUMMARY_HEADERS[col], justify="right", no_wrap=True, min_width=widths[col]
        )
    for row, r in zip(rows, cells, strict=True):
        label = (
            row["controller"] if row["params"] == "-" else f"{row['controller']}\n{row['params']}"
        )
        shown = [c for col, c in zip(numeric, r, strict=True) if col in kept]
        table.add_row(_text(label), *(_text(c) for c in shown))
    con.print(table)
    if failures:
        _print_failures(failed)
    speed = f", {rate:.2f} episodes/s" if rate is not None else ""
    typer.echo(
        f"ran {result.ran} episode(s) ({result.errors} error(s)), skipped {result.skipped} already "
        f"stored, in {elapsed:.1f} s{speed} on {engine} × {n_workers}; results in {db}"
    )
    _fail_on_errors(result.errors, first_error)


def _mcap_folder(folder: Path) -> Any:
    """The campaign's probe factory writing episodes into ``folder``
    (:class:`uvnav.bags.mcap.McapFolder`), the folder made if missing.

    Raises:
        CliError: the folder cannot be made (status 2); the ``ros`` extra missing (status 1).
    """
    from uvnav.bags import MissingExtraError, require
    from uvnav.bags.mcap import McapFolder

    try:
        require("--mcap-dir")
    except MissingExtraError as exc:
        raise CliError(str(exc), code=1) from None
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise CliError(f"--mcap-dir {folder}: is a file; give a folder") from None
    except OSError as exc:
        raise CliError(f"--mcap-dir {folder}: cannot make it: {exc.strerror or exc}") from None
    return McapFolder(folder.resolve())


def _print_failures(rows: list[dict[str, Any]]) -> None:
    """The episodes that did not succeed (``uvnav bench --failures``), each as one line of law,
    seed, cause and clearance, then the ``uvnav simulate`` command that runs it again, on one
    line however wide (so that it can be copied)."""
    con = _console()
    con.print(f"\n{len(rows)} episode(s) did not succeed; each reruns with the command below it:")
    for r in rows:
        law = r["controller"] if r["params"] == "-" else f"{r['controller']} {r['params']}"
        gap = "" if r["min_clearance"] is None else f", clearance {r['min_clearance']:.3f} m"
        con.print(f"- {law}, seed {r['seed']}: {r['cause']}{gap}", markup=False, highlight=False)
        con.print(f"  {r['command']}", markup=False, highlight=False, soft_wrap=True)


def _first_error(store: Any, campaign: str) -> str | None:
    """The message of the first stored ``error`` episode of ``campaign``, with its job."""
    frame = store.episodes_frame(campaign)
    bad = frame[frame["status"] == "error"]
    if bad.empty:
        return None
    row = bad.iloc[0]
    message = one_line(str(row["error"]))
    return f"{row['scenario']} | {row['controller']} | seed {row['seed']}: {message}"


def _fail_on_errors(errors: int, first: str | None) -> None:
    """Exit status 1 when episodes errored (their rows are kept, as ``error``)."""
    if errors:
        typer.echo(f"error: {errors} episode(s) errored; the first: {first}", err=True)
        raise typer.Exit(1)
