"""Helpers shared by the command modules: rich output, strict JSON, optional parts, and the
``--param`` / ``--gen-param`` parsing and scene resolution that ``simulate`` and ``scenarios``
both use.

Every command module (:mod:`uvnav.cli.app`, :mod:`uvnav.cli.reproduce`, ...) may import this one;
it imports no command module, so the command modules never import each other for a helper.
"""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer
import yaml

from uvnav.cli.checks import dumps as strict_dumps
from uvnav.cli.checks import json_safe
from uvnav.cli.errors import CliError
from uvnav.scenarios.loader import yaml_value
from uvnav.validation import clip


def console(stderr: bool = False) -> Any:
    """A rich console; into a file or a pipe, wide enough that no identifier is cut."""
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    width = None if stream.isatty() else 1000
    return Console(stderr=stderr, highlight=False, width=width)


def text(value: Any) -> Any:
    """``value`` as rich text, shown as it is (no markup)."""
    from rich.text import Text

    return Text(str(value))


def fmt(value: Any) -> str:
    """A table cell: ``-`` for none, ``yes``/``no``, integers whole, floats to 4 digits."""
    if value is None:
        return "-"
    if isinstance(value, bool | np.bool_):
        return "yes" if value else "no"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        return f"{float(value):.4g}"
    return str(value)


def _jsonable(value: Any) -> Any:
    """``json.dumps`` fallback: numpy values and paths as JSON data (non-finite floats: null)."""
    if isinstance(value, np.generic | np.ndarray | Path):
        return json_safe(value)
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def dumps(data: Any, *, indent: int | None = None) -> str:
    """Strict JSON: a NaN/±inf float (a missing value) is printed as ``null``, never ``NaN``."""
    return strict_dumps(data, indent=indent, default=_jsonable)


def optional(module: str, attr: str, what: str) -> Any:
    """``module.attr`` imported on demand; a missing part is a one-line error (status 1)."""
    try:
        mod = importlib.import_module(module)
    except ImportError as exc:
        raise CliError(f"{what} is not available: cannot import {module} ({exc})", code=1) from None
    obj = getattr(mod, attr, None)
    if obj is None:
        raise CliError(f"{what} is not available: {module} has no {attr!r}", code=1)
    return obj


def compact_table(title: str, caption: str | None = None) -> Any:
    """A rich table with a rule under its header only, no outer padding: the summaries'."""
    from rich import box
    from rich.table import Table

    return Table(title=title, caption=caption, box=box.SIMPLE_HEAD, pad_edge=False,
                 collapse_padding=True)  # fmt: skip


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


#: ``--param/-p KEY=VALUE``: a law's parameters (:func:`parse_params` reads them)
ParamOption = Annotated[
    list[str] | None,
    typer.Option(
        "--param",
        "-p",
        metavar="KEY=VALUE",
        help="Law parameter KEY=VALUE (repeatable; value read as YAML).",
    ),
]
#: ``--controller/-c NAME``: the law to run, the scene's own when not given
ControllerOption = Annotated[
    str | None,
    typer.Option("--controller", "-c", help="Law name (default: the scenario's)."),
]

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
