"""The ``uvnav`` command line (layer 8): thin Typer commands over the library.

Commands parse their arguments, call the library and print with rich (or plain JSON/YAML where the
output is meant for machines).  Errors take one path, :class:`~uvnav.cli.errors.UvnavGroup`: a
user error — a bad scenario file, an unknown controller or parameter, a missing file, a malformed
``--param`` — is ONE line ``error: <message>`` on stderr and exit status 2; a bug is ONE line
``internal error: ...`` naming the crash log that holds its traceback, exit status 70
(``uvnav --debug`` shows the traceback instead).

Heavy or optional parts (the reproduction job, figures, the report) are imported inside the
command that needs them, so ``uvnav scenarios list`` stays fast and works without them.
"""

from __future__ import annotations

import dataclasses
import inspect
import re
import shutil
import sys
from pathlib import Path
from typing import Annotated, Any

import typer
import yaml

from uvnav.cli.checks import too_many_workers
from uvnav.cli.common import compact_table
from uvnav.cli.common import console as _console
from uvnav.cli.common import dumps as _dumps
from uvnav.cli.common import fmt as _fmt
from uvnav.cli.common import optional as _optional
from uvnav.cli.common import text as _text
from uvnav.cli.drive import drive_app
from uvnav.cli.errors import (
    DEBUG_KEY,
    CliError,
    one_line,
    uvnav_typer,
)
from uvnav.cli.recon import recon_app
from uvnav.cli.reproduce import forget_cmd, reproduce_cmd, run_cmd
from uvnav.cli.sonar import sonar_app
from uvnav.controllers import (
    ControllerInfo,
    UnknownControllerError,
    available_controllers,
    controller_info,
)
from uvnav.dynamics.vehicles import vehicle_names
from uvnav.scenarios import (
    ScenarioError,
    check_constraints,
)
from uvnav.scenarios.loader import yaml_value
from uvnav.sim import METRIC_NAMES
from uvnav.sim.metrics import SOCIAL_METRIC_NAMES
from uvnav.validation import clip

# ---------------------------------------------------------------------------------- error handling
# One path for every command (see uvnav.cli.errors): user errors are one ``error:`` line and exit
# status 2, bugs one ``internal error:`` line (traceback in a crash log) and exit status 70.

_one_line = one_line


def _first_sentence(text: str) -> str:
    """Up to the first full stop that ends a sentence (not the one in "Fig. 2.7")."""
    if not text.strip():
        return ""
    return re.split(r"(?<=[a-z0-9)\]])\.\s+(?=[A-Z])", text, maxsplit=1)[0].rstrip(".") + "."


app = uvnav_typer(
    name="uvnav",
    help="Real-time navigation of unmanned vehicles: simulate, benchmark and report.",
)
scenarios_app = uvnav_typer(help="Built-in and user scenarios.")
controllers_app = uvnav_typer(help="Registered navigation laws.")
app.add_typer(scenarios_app, name="scenarios")
app.add_typer(controllers_app, name="controllers")
app.add_typer(recon_app, name="recon")
app.add_typer(drive_app, name="drive")
app.add_typer(sonar_app, name="sonar")
app.add_typer(__import__("uvnav.cli.ros2", fromlist=["ros2_app"]).ros2_app, name="ros2")


def _version(value: bool) -> None:
    if value:
        from uvnav import __version__

        typer.echo(f"uvnav {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    ctx: typer.Context,
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
    debug: Annotated[
        bool,
        typer.Option(
            "--debug",
            help="On an internal error, show the Python traceback instead of writing it to a "
            "crash log (also: UVNAV_DEBUG=1).",
        ),
    ] = False,
) -> None:
    """Real-time navigation of unmanned vehicles: simulate, benchmark and report."""
    if debug:
        ctx.meta[DEBUG_KEY] = True


# ----------------------------------------------------------------------------------------- helpers


_PARAM_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def parse_params(items: list[str] | None, option: str = "--param") -> dict[str, Any]:
    """``["alpha0=0.1", "mode=fast"]`` -> ``{"alpha0": 0.1, "mode": "fast"}`` (values read as YAML).

    Raises:
        CliError: an item is not ``KEY=VALUE`` with an identifier key, or its value is not YAML.
    """
    params: dict[str, Any] = {}
    for item in items or []:
        key, sep, raw = item.partition("=")
        key = key.strip()
        shown = repr(clip(item, 60))
        if not sep or not _PARAM_KEY.match(key):
            raise CliError(
                f"{option} {shown}: expected KEY=VALUE with an identifier KEY (e.g. alpha0=0.1)"
            )
        try:
            value = yaml_value(raw) if raw.strip() else ""
        except yaml.YAMLError as exc:
            marked = isinstance(exc, yaml.MarkedYAMLError)
            why = "not a valid YAML scalar or list" if marked else exc
            raise CliError(f"{option} {shown}: value is {why}") from None
        params[key] = value
    return params


_METRIC_UNITS = {
    "min_clearance": "m",
    "path_length": "m",
    "time_to_goal": "s",
    "control_effort": "rad²/s + m²/s³",
    "decision_us_median": "µs",
    "decision_us_p99": "µs",
    "min_separation": "m",
    "too_close_time": "s",
    "intrusion_time": "s",
    "path_irregularity": "rad/m",
    "contact_time": "s",
}


GenParamOption = Annotated[
    list[str] | None,
    typer.Option(
        "--gen-param",
        metavar="KEY=VALUE",
        help="Generator parameter KEY=VALUE of a GENERATOR:SEED scene (repeatable; value read "
        "as YAML), e.g. speed_ratio_max=0.9; 'uvnav scenarios show GENERATOR' lists them.",
    ),
]


def resolve_scene(spec: str, gen_param: list[str] | None) -> Any:
    """The scene ``spec`` names (:func:`uvnav.scenarios.catalog.resolve`), drawn with the
    ``--gen-param`` values when there are any (a ``GENERATOR:SEED`` spec only)."""
    from uvnav.scenarios.catalog import generate, generators, resolve

    items = parse_params(gen_param, "--gen-param").items()
    if not items:
        return resolve(spec)
    params = dict(items)
    by_gen = generators()
    gen, sep, number = spec.partition(":")
    if not (sep and gen in by_gen and by_gen[gen].spec_is_seed):
        raise CliError(f"--gen-param: only a GENERATOR:SEED scene takes them (got {spec!r})")
    if not number.isdigit():
        raise CliError(f"{spec}: seed: must be a non-negative integer (got {number!r})")
    return generate(gen, int(number), params)


# ---------------------------------------------------------------------------------------- simulate


@app.command()
def simulate(
    scenario: Annotated[
        str,
        typer.Argument(
            help="Built-in name, YAML file, or GENERATOR:SEED (random-ch2:3, random-ch4:1, "
            "antipodal:8 = 8 robots; see 'uvnav scenarios list')."
        ),
    ],
    controller: Annotated[
        str | None,
        typer.Option("--controller", "-c", help="Law name (default: the scenario's)."),
    ] = None,
    param: Annotated[
        list[str] | None,
        typer.Option(
            "--param",
            "-p",
            metavar="KEY=VALUE",
            help="Law parameter KEY=VALUE (repeatable; value read as YAML).",
        ),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(
            min=0,
            help="Episode seed (obstacle motion, sensing noise); default 0, or the generator's "
            "seed for GENERATOR:SEED.",
        ),
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON object instead of the table.")
    ] = False,
    plot: Annotated[
        Path | None, typer.Option(help="Also draw the episode into this image file.")
    ] = None,
    gen_param: GenParamOption = None,
    beyond_assumptions: Annotated[
        bool,
        typer.Option(
            "--beyond-assumptions",
            help="Run the law even where the scene breaks an assumption it declares (a "
            "deliberate experiment, as a campaign's beyond_assumptions: true).",
        ),
    ] = False,
) -> None:
    """Run one episode of SCENARIO (any vehicle) and print its metrics.

    The scenario's law parameters are used when the law is the scenario's own; --param values
    override them.  With another --controller only --param values apply.  A law that drives
    another vehicle or reads another sensor than the scene's is refused, and so is one whose
    declared assumption the scene breaks, unless --beyond-assumptions.
    """
    from uvnav.scenarios.episodes import limits_note, run_scene

    if controller is not None and not controller.strip():
        raise CliError("--controller '': empty law name ('uvnav controllers list' names them)")
    resolved = resolve_scene(scenario, gen_param)
    plot_outcome = (
        _optional("uvnav.viz.episode", "plot_outcome", "plotting (--plot)") if plot else None
    )
    if plot is not None:
        _check_image_path(plot)
    out = run_scene(
        resolved,
        controller,
        parse_params(param),
        seed,
        record=plot is not None,
        beyond_assumptions=beyond_assumptions,
    )
    note = limits_note(resolved, out.law)
    if note is not None:
        typer.echo(note, err=True)
    record: dict[str, Any] = {
        "scenario": out.scene,
        "kind": out.kind,
        "controller": out.law,
        "params": out.params,
        "seed": out.seed,
        "status": out.status,
        **{k: out.metrics[k] for k in METRIC_NAMES},
        **out.extra,
    }
    if plot_outcome is not None and plot is not None:
        try:
            plot_outcome(out, plot)
        except ValueError as exc:
            raise CliError(str(exc)) from None
        except ImportError as exc:
            raise CliError(f"plotting (--plot) is not available: {exc}", code=1) from None
    if json_out:
        typer.echo(_dumps(record))
        if plot is not None:
            typer.echo(f"wrote {plot}", err=True)
        return
    from rich.table import Table

    table = Table(title=f"{out.scene} | {out.law} | seed {out.seed} | {out.status}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    table.add_column("unit")
    for key in METRIC_NAMES:
        if key in SOCIAL_METRIC_NAMES and out.kind != "nav2d":
            continue  # only the 2D worlds have them (uvnav.sim.social); JSON keeps them as null
        table.add_row(key, _fmt(out.metrics[key]), _METRIC_UNITS.get(key, ""))
    for key, value in out.extra.items():
        if not isinstance(value, dict | list):
            table.add_row(key, _fmt(value), _METRIC_UNITS.get(key, ""))
    con = _console()
    con.print(table)
    robots = out.extra.get("robots")
    if robots:
        for row in robots:
            t = row["time_to_goal"]
            con.print(
                _text(
                    f"  {row['name']:>12}  {row['status']:<9}  path {row['path_length']:.2f} m"
                    + (f"  arrived {t:.1f} s" if t is not None else "")
                )
            )
    if plot is not None:
        typer.echo(f"wrote {plot}")


# --------------------------------------------------------------------------------------- scenarios


def _scene_description(sc: Any) -> str:
    return _one_line(str(getattr(sc, "description", "") or ""))


@scenarios_app.command("list")
def scenarios_list(
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON array instead of the table.")
    ] = False,
) -> None:
    """List the built-in scenes of every kind (thesis experiments first) and the generators
    (one line each with its parameters' names; 'uvnav scenarios show GENERATOR' describes them)."""
    from uvnav.scenarios.catalog import (
        builtin_names,
        generator_params,
        generator_summary,
        generators,
    )

    rows: list[dict[str, Any]] = []
    for name, kind in builtin_names():
        sc = kind.load(name)
        rows.append(
            {
                "name": name,
                "kind": kind.name,
                "description": _scene_description(sc),
                "obstacles": len(getattr(sc, "obstacles", []) or []),
                "controller": sc.controller.name,
            }
        )
    for gen, kind in generators().items():
        number = "<seed>" if kind.spec_is_seed else "<robots>"
        names = [p.name for p in generator_params(gen)] if kind.spec_is_seed else []
        rows.append(
            {
                "name": f"{gen}:{number}",
                "kind": kind.name,
                "description": (generator_summary(gen) or f"generator of {kind.summary} scenes")
                + (f" (params: {', '.join(names)})" if names else ""),
                "params": names,
                "obstacles": None,
                "controller": None,
            }
        )
    if json_out:
        typer.echo(_dumps(rows))
        return
    width = max(len(r["name"]) for r in rows)
    cols = shutil.get_terminal_size().columns if sys.stdout.isatty() else None
    typer.echo(f"{'name':<{width}}  {'kind':<7}  description ('uvnav scenarios show NAME')")
    for row in rows:
        text = row["description"] if row.get("params") else _first_sentence(row["description"])
        line = f"{row['name']:<{width}}  {row['kind']:<7}  {text}"
        if cols is not None and len(line) > cols:
            line = line[: cols - 1] + "…"
        typer.echo(line.rstrip())


def _model_yaml(model: Any) -> str:
    from uvnav.scenarios.loader import scenario_to_yaml
    from uvnav.scenarios.schema import Scenario

    if isinstance(model, Scenario):
        return scenario_to_yaml(model)
    import yaml

    return str(yaml.safe_dump(model.model_dump(mode="json"), sort_keys=False))


def _show_generator_params(name: str) -> None:
    """The parameter table of seed generator ``name``."""
    from uvnav.scenarios.catalog import generator_params

    params = generator_params(name)
    typer.echo(f"{name}:SEED parameters (--gen-param KEY=VALUE; params: in a campaign entry)")
    if not params:
        typer.echo("  (none)")
    width = max((len(p.name) for p in params), default=0)
    for p in params:
        bounds = f", {p.bounds}" if p.bounds else ""
        text = f"  {p.name:<{width}}  {p.type} = {p.default!r}{bounds}"
        typer.echo(f"{text}  {p.description}".rstrip())


@scenarios_app.command("show")
def scenarios_show(
    name: Annotated[
        str,
        typer.Argument(
            help="Built-in name, YAML file, GENERATOR:SEED, or a GENERATOR (its parameters)."
        ),
    ],
    resolved: Annotated[
        bool,
        typer.Option(
            "--resolved", help="Print the validated scenario with every default filled in."
        ),
    ] = False,
    gen_param: GenParamOption = None,
) -> None:
    """Print a scenario as YAML (the file as written; a generated one, or --resolved, with
    every default filled in), or a generator's parameters."""
    from uvnav.scenarios.catalog import generators

    by_gen = generators()
    if name in by_gen and by_gen[name].spec_is_seed:
        _show_generator_params(name)
        return
    res = resolve_scene(name, gen_param)
    if gen_param:
        typer.echo(_model_yaml(res.scenario), nl=False)
        return
    if resolved or res.spec.partition(":")[1]:
        typer.echo(_model_yaml(res.scenario), nl=False)
        return
    from uvnav.scenarios.loader import builtin_yaml_files

    path = Path(name)
    if not path.is_file():
        subdir = {"uuv2d": "ch4", "uuv3d": "ch5"}.get(res.kind.name, "")
        path = builtin_yaml_files(subdir)[name]
    text = path.read_text()
    typer.echo(text, nl=not text.endswith("\n"))


@scenarios_app.command("schema")
def scenarios_schema(
    kind: Annotated[
        str | None,
        typer.Option(help="Only this kind's schema (nav2d, nav3d, uuv2d, uuv3d, multi2d)."),
    ] = None,
) -> None:
    """Print the JSON Schema of scenario files (every kind: one of the kinds' models)."""
    from uvnav.scenarios.catalog import KINDS, kinds, scene_file_adapter

    if kind is None:
        typer.echo(_dumps(scene_file_adapter().json_schema(), indent=2))
        return
    if kind not in KINDS:
        raise CliError(f"--kind: unknown kind {kind!r}; known: {', '.join(KINDS)}")
    typer.echo(_dumps(kinds()[kind].model.model_json_schema(), indent=2))  # type: ignore[attr-defined]


@scenarios_app.command("validate")
def scenarios_validate(
    files: Annotated[list[str], typer.Argument(help="Scenario files (or built-in names).")],
) -> None:
    """Check scenario files of any kind: OK, or one error line each, plus the law's assumption
    warnings ((2.6)-(2.8) for the 2D scenes).

    Exit status 2 when any file is invalid.
    """
    from uvnav.scenarios.catalog import resolve
    from uvnav.scenarios.episodes import check_law

    invalid = 0
    for item in files:
        try:
            res = resolve(item)
        except ScenarioError as exc:
            typer.echo(f"error: {exc}", err=True)
            invalid += 1
            continue
        sc = res.scenario
        warnings = (
            [f"{item}: {w}" for w in check_constraints(sc)] if res.kind.name == "nav2d" else []
        )
        try:
            check_law(res, sc.controller.name, params=dict(getattr(sc.controller, "params", {})))
        except ScenarioError as exc:
            typer.echo(f"error: {item}: {exc.path}: {exc.problem}", err=True)
            invalid += 1
            continue
        except UnknownControllerError:
            warnings.append(
                f"{item}: controller.name: {sc.controller.name!r} is not a registered controller"
            )
        suffix = (
            f" ({len(warnings)} warning{'s' if len(warnings) != 1 else ''})" if warnings else ""
        )
        typer.echo(f"OK {item} [{res.kind.name}]{suffix}")
        for w in warnings:
            typer.echo(f"  warning: {w}")
    if invalid:
        raise typer.Exit(2)


# ------------------------------------------------------------------------------------- controllers


def attribute_docs(cls: type) -> dict[str, str]:
    """Field descriptions from the ``Attributes:`` section of a Google-style class docstring."""
    doc = inspect.getdoc(cls) or ""
    out: dict[str, str] = {}
    in_section = False
    indent: int | None = None
    current: str | None = None
    for line in doc.splitlines():
        stripped = line.strip()
        if stripped in ("Attributes:", "Args:", "Parameters:"):
            in_section, indent, current = True, None, None
            continue
        if not in_section:
            continue
        if not stripped:
            current = None
            continue
        level = len(line) - len(line.lstrip())
        if level == 0:
            in_section = False
            continue
        match = re.match(r"^(\w+)(?:\s*\([^)]*\))?:\s*(.*)$", stripped)
        if match and (indent is None or level == indent):
            indent = level
            current = match.group(1)
            out[current] = match.group(2)
        elif current is not None:
            out[current] = f"{out[current]} {stripped}".strip()
    return out


def _param_rows(info: ControllerInfo) -> list[dict[str, Any]]:
    ptype = info.params_type
    if ptype is None or not dataclasses.is_dataclass(ptype):
        return []
    docs = attribute_docs(ptype)
    rows = []
    for f in dataclasses.fields(ptype):
        if f.default is not dataclasses.MISSING:
            default: Any = f.default
        elif f.default_factory is not dataclasses.MISSING:
            default = f.default_factory()
        else:
            default = None
        type_name = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type))
        rows.append(
            {"name": f.name, "type": type_name, "default": default, "doc": docs.get(f.name, "")}
        )
    return rows


@controllers_app.command("list")
def controllers_list(
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON array instead of the table.")
    ] = False,
    vehicle: Annotated[
        str | None,
        typer.Option(
            "--vehicle",
            help="Only one vehicle's laws: unicycle (Ch. 2), vehicle3d (Ch. 3/5), uuv2d (Ch. 4).",
        ),
    ] = None,
) -> None:
    """List the registered controllers of every vehicle (or of one)."""
    if vehicle is not None and vehicle not in vehicle_names():
        known = ", ".join(vehicle_names())
        raise CliError(f"--vehicle: unknown vehicle {vehicle!r}; known: {known}")
    infos = available_controllers(vehicle)
    rows = [
        {
            "name": name,
            "vehicle": info.vehicle,
            "sensing": info.sensing,
            "summary": info.summary,
            "reference": info.reference,
            "requires_slower_obstacles": info.requires_slower_obstacles,
        }
        for name, info in infos.items()
    ]
    if json_out:
        typer.echo(_dumps(rows))
        return
    from rich.table import Table

    table = Table(title="controllers")
    table.add_column("name", no_wrap=True)
    table.add_column("vehicle", no_wrap=True)
    table.add_column("sensing", no_wrap=True)
    table.add_column("summary")
    table.add_column("slower obstacles")
    for row in rows:
        table.add_row(
            _text(row["name"]),
            _text(row["vehicle"]),
            _text(row["sensing"]),
            _text(row["summary"]),
            "required" if row["requires_slower_obstacles"] else "",
        )
    _console().print(table)


@controllers_app.command("show")
def controllers_show(
    name: Annotated[str, typer.Argument(help="Registered controller name, e.g. zhang2019-v1.")],
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON object instead of the table.")
    ] = False,
) -> None:
    """Show a controller: summary, reference and parameters with defaults and units."""
    info = controller_info(name)
    rows = _param_rows(info)
    if json_out:
        typer.echo(
            _dumps(
                {
                    "name": info.name,
                    "summary": info.summary,
                    "reference": info.reference,
                    "requires_slower_obstacles": info.requires_slower_obstacles,
                    "params": rows,
                }
            )
        )
        return
    from rich.table import Table

    con = _console()
    con.print(_text(f"{info.name}: {info.summary}"))
    if info.reference:
        con.print(_text(f"reference: {info.reference}"))
    if info.requires_slower_obstacles:
        con.print(_text("requires obstacles slower than the robot (thesis (2.6))"))
    if not rows:
        con.print(_text("no parameters"))
        return
    table = Table(title="parameters")
    table.add_column("name", no_wrap=True)
    table.add_column("type")
    table.add_column("default", justify="right")
    table.add_column("description")
    for row in rows:
        table.add_row(
            _text(row["name"]), _text(row["type"]), _text(_fmt(row["default"])), _text(row["doc"])
        )
    con.print(table)


# ------------------------------------------------------------------------------------- run / report


app.command("run")(run_cmd)


@app.command("report")
def report_cmd(
    db: Annotated[
        Path, typer.Argument(help="Results database (SQLite) written by uvnav run / bench.")
    ],
    out: Annotated[Path, typer.Option("--out", help="Output directory.")] = Path("report"),
    bench: Annotated[
        Path | None,
        typer.Option(
            "--bench",
            help="Folder of benchmark JSON (make bench, benchmarks/peers/) to add as a section.",
        ),
    ] = None,
) -> None:
    """Turn a results database into the HTML report (the database is only read)."""
    if not db.exists():
        raise CliError(f"{db}: no such database file")
    if not db.is_file():
        raise CliError(f"{db}: not a file")
    if bench is not None and not bench.is_dir():
        raise CliError(f"{bench}: --bench must be a folder of benchmark JSON files")
    from uvnav.bench.store import NotAStoreError, ResultsStore

    try:  # before anything is written: a foreign or empty file is refused as it is
        ResultsStore(db, readonly=True).close()
    except NotAStoreError as exc:
        raise CliError(str(exc)) from None
    write_report = _optional("uvnav.viz.report", "write_report", "the report (uvnav report)")
    from uvnav.experiments import report_sections

    sections = report_sections(db)  # saved by the experiments' runs, or rebuilt from stored rows
    try:
        path = write_report(
            db,
            out,
            bench_dir=bench,
            sections=sections,
            table=[r for s in sections for r in s.rows],
        )
    except ValueError as exc:
        raise CliError(str(exc)) from None
    typer.echo(f"wrote {path}")


# ------------------------------------------------------------------------------------------ bench

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


@app.command()
def bench(
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
        str | None, typer.Option(help="Ray cluster address (--engine ray; default: local Ray).")
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
            help="Also list every episode that did not succeed: seed and cause (who closed the "
            "gap at a collision, or timeout / refused / error).  With --resume on a finished "
            "campaign: only the listing.",
        ),
    ] = False,
) -> None:
    """Run a benchmark campaign into a results database, then print a per-controller summary.

    Each finished episode is stored at once (one transaction), so an interrupted campaign resumes
    with --resume and never duplicates an episode.
    """
    import os
    import time

    from uvnav.bench.campaign import ENGINES
    from uvnav.bench.ray_engine import EngineUnavailableError, import_ray
    from uvnav.bench.spec import load_campaign, run_campaign_spec
    from uvnav.bench.store import ResultsStore, StoreInUseError
    from uvnav.bench.summary import SUMMARY_COLUMNS, controller_summary, failure_rows

    if engine not in ENGINES:
        raise CliError(f"--engine {engine!r}: expected one of {', '.join(ENGINES)}")
    if address is not None and engine != "ray":
        raise CliError("--address needs --engine ray")
    spec = load_campaign(campaign)
    if engine == "ray":
        try:
            import_ray()  # before the database is created
        except EngineUnavailableError as exc:
            raise CliError(str(exc), code=1) from None
    n_workers = workers or os.cpu_count() or 1
    too_many = too_many_workers(n_workers) if engine == "local" else None  # Ray: a cluster's
    if too_many is not None:
        raise CliError(f"--workers: {too_many} for --engine local")
    with ResultsStore(db) as store:
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
            )
        except EngineUnavailableError as exc:
            raise CliError(str(exc), code=1) from None
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
        failed = failure_rows(store, spec.name) if failures else []
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
    table = compact_table(f"campaign {spec.name} ({result.total} episodes)")
    numeric = [c for c in SUMMARY_COLUMNS if c in _SUMMARY_HEADERS]
    table.add_column("controller\nparams", overflow="fold", ratio=1, min_width=12)
    cells = [[_summary_cell(col, row[col]) for col in numeric] for row in rows]
    for i, col in enumerate(numeric):
        widest = max(len(r[i]) for r in cells) if cells else 1
        head = _SUMMARY_HEADERS[col]
        width = max(widest, *(len(w) for w in head.split("\n")))
        table.add_column(head, justify="right", no_wrap=True, min_width=width)
    for row, r in zip(rows, cells, strict=True):
        label = (
            row["controller"] if row["params"] == "-" else f"{row['controller']}\n{row['params']}"
        )
        table.add_row(_text(label), *(_text(c) for c in r))
    _console().print(table)
    if failures:
        _print_failures(failed, spec.beyond_assumptions)
    speed = f", {rate:.2f} episodes/s" if rate is not None else ""
    typer.echo(
        f"ran {result.ran} episode(s) ({result.errors} error(s)), skipped {result.skipped} already "
        f"stored, in {elapsed:.1f} s{speed} on {engine} × {n_workers}; results in {db}"
    )
    _fail_on_errors(result.errors, first_error)


def _check_image_path(path: Path) -> None:
    """Refuse, before any work, an image path matplotlib would not write as given: a folder, or
    a name without a format suffix it knows (it would write ``NAME.png`` beside it instead).

    Raises:
        CliError: one line naming the path and the formats.
    """
    from matplotlib.backend_bases import FigureCanvasBase

    formats = FigureCanvasBase.get_supported_filetypes()
    if path.is_dir():
        raise CliError(f"--plot {path}: is a directory; give an image file such as run.png")
    if path.suffix.lower().lstrip(".") not in formats:
        raise CliError(
            f"--plot {path}: unknown image format {path.suffix or '(no suffix)'}; "
            f"use one of {', '.join('.' + f for f in sorted(formats))}"
        )


def _print_failures(rows: list[dict[str, Any]], beyond: bool) -> None:
    """The episodes that did not succeed, one line each (``uvnav bench --failures``); the
    scenario as ``uvnav simulate`` takes it, so that a row reruns as it is (with
    ``--beyond-assumptions`` when the campaign ran ``beyond``)."""
    from uvnav.bench.summary import simulate_spec

    flag = " --beyond-assumptions" if beyond else ""
    table = compact_table(
        f"{len(rows)} episode(s) did not succeed",
        caption=f"rerun one: uvnav simulate SCENARIO -c CONTROLLER --seed SEED{flag} "
        "(its params as -p)",
    )
    for head in ("controller", "scenario", "seed"):
        table.add_column(head, overflow="fold")
    table.add_column("cause", overflow="fold", ratio=1)
    table.add_column("clearance\n[m]", justify="right", no_wrap=True)
    for r in rows:
        law = r["controller"] if r["params"] == "-" else f"{r['controller']} {r['params']}"
        gap = "-" if r["min_clearance"] is None else f"{r['min_clearance']:.3f}"
        scene = simulate_spec(r["scenario"])
        table.add_row(*(_text(x) for x in (law, scene, str(r["seed"]), r["cause"], gap)))
    _console().print(table)


def _first_error(store: Any, campaign: str) -> str | None:
    """The message of the first stored ``error`` episode of ``campaign``, with its job."""
    frame = store.episodes_frame(campaign)
    bad = frame[frame["status"] == "error"]
    if bad.empty:
        return None
    row = bad.iloc[0]
    message = _one_line(str(row["error"]))
    return f"{row['scenario']} | {row['controller']} | seed {row['seed']}: {message}"


def _fail_on_errors(errors: int, first: str | None) -> None:
    """Exit status 1 when episodes errored (their rows are kept, as ``error``)."""
    if errors:
        typer.echo(f"error: {errors} episode(s) errored; the first: {first}", err=True)
        raise typer.Exit(1)


def main() -> None:
    """Console-script entry point (``uvnav``)."""
    app(prog_name="uvnav")


app.command("reproduce")(reproduce_cmd)
app.command("forget")(forget_cmd)
