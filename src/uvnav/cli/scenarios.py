"""``uvnav scenarios``: list, show, schema and validate the scenes of every kind.

Thin Typer commands over :mod:`uvnav.scenarios`; a bad scenario file is a one-line ``error:``
and exit status 2 (the CLI's one error path, :mod:`uvnav.cli.errors`).
"""

from __future__ import annotations

import re
import shutil
import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from uvnav.cli.common import GenParamOption, resolve_scene
from uvnav.cli.common import dumps as _dumps
from uvnav.cli.errors import CliError, one_line, uvnav_typer
from uvnav.controllers import UnknownControllerError
from uvnav.scenarios import ScenarioError, check_constraints

scenarios_app = uvnav_typer(help="Built-in and user scenarios.")


def _first_sentence(text: str) -> str:
    """Up to the first full stop that ends a sentence (not the one in "Fig. 2.7")."""
    if not text.strip():
        return ""
    return re.split(r"(?<=[a-z0-9)\]])\.\s+(?=[A-Z])", text, maxsplit=1)[0].rstrip(".") + "."


def _scene_description(sc: Any) -> str:
    return one_line(str(getattr(sc, "description", "") or ""))


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
