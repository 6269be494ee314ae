"""The built-in scenario library, and loading a scenario by name.

A scenario is named either by a path to a YAML file or by the name of a built-in (the YAML files
shipped in ``uvnav/scenarios/builtin/``, thesis experiments first), or by a generator spec
``random-ch2:<seed>`` (see :func:`uvnav.scenarios.generators.random_ch2_scenario`).  Every
problem is raised as a one-line :class:`~uvnav.scenarios.errors.ScenarioError`.  Parsing and
validating the YAML is :mod:`uvnav.scenarios.parse`'s (its functions are importable from here too).
"""

from __future__ import annotations

import re
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.generators import GENERATORS
from uvnav.scenarios.parse import (
    allowed_fields,
    parse_yaml,
    scenario_from_dict,
    scenario_to_dict,
    scenario_to_yaml,
    yaml_value,
)
from uvnav.scenarios.schema import Scenario

__all__ = [
    "BUILTIN_DIR",
    "BUILTIN_PACKAGE",
    "allowed_fields",
    "builtin_text",
    "builtin_yaml_files",
    "list_builtin",
    "load_scenario",
    "natural_key",
    "parse_yaml",
    "scenario_from_dict",
    "scenario_text",
    "scenario_to_dict",
    "scenario_to_yaml",
    "yaml_value",
]

BUILTIN_PACKAGE = "uvnav.scenarios"
BUILTIN_DIR = "builtin"


def natural_key(name: str) -> list[Any]:
    """Sort key putting ``fig2-9`` before ``fig2-10``."""
    return [int(tok) if tok.isdigit() else tok for tok in re.split(r"(\d+)", name)]


@cache
def builtin_yaml_files(subdir: str = "") -> dict[str, Any]:
    """The YAML files of the built-in scenario folder ``builtin/<subdir>`` by name (no suffix).

    The top folder holds the 2D scenes; chapters whose scenes have their own schema keep them in
    a sub-folder (``builtin/ch4``, ``builtin/ch5``).
    """
    root = resources.files(BUILTIN_PACKAGE).joinpath(BUILTIN_DIR)
    if subdir:
        root = root.joinpath(subdir)
    out: dict[str, Any] = {}
    if root.is_dir():
        for entry in root.iterdir():
            if entry.name.endswith((".yaml", ".yml")):
                out[entry.name.rsplit(".", 1)[0]] = entry
    return out


def _builtin_files() -> dict[str, Any]:
    return builtin_yaml_files()


def list_builtin() -> list[str]:
    """Names of the built-in scenarios: thesis experiments (``thesis-*``) first, then the others.

    Each group is sorted in natural order (``fig2-9`` before ``fig2-10``).
    """
    names = sorted(_builtin_files(), key=natural_key)
    return [n for n in names if n.startswith("thesis-")] + [
        n for n in names if not n.startswith("thesis-")
    ]


def builtin_text(name: str) -> str:
    """The YAML text of built-in scenario ``name`` (comments included).

    Raises:
        ScenarioError: unknown name.
    """
    files = _builtin_files()
    if name not in files:
        raise ScenarioError(
            name, "", f"unknown built-in scenario (known: {', '.join(list_builtin())})"
        )
    return str(files[name].read_text(encoding="utf-8"))


def _looks_like_path(text: str) -> bool:
    return text.endswith((".yaml", ".yml")) or "/" in text or "\\" in text


def scenario_text(name_or_path: str | Path) -> tuple[str, str]:
    """``(source, YAML text)`` of a built-in name or a file path (no validation).

    Raises:
        ScenarioError: no such file or built-in, or the file cannot be read.
    """
    try:
        Path(name_or_path).exists()
    except OSError as exc:  # a name longer than the system allows
        raise ScenarioError(str(name_or_path), "", exc.strerror or str(exc)) from None
    if isinstance(name_or_path, str) and not _looks_like_path(name_or_path):
        if name_or_path in _builtin_files():
            return f"{name_or_path}.yaml", builtin_text(name_or_path)
        if not Path(name_or_path).is_file():
            raise ScenarioError(
                name_or_path,
                "",
                "no such file or built-in scenario "
                f"(built-ins: {', '.join(list_builtin())}; generators: <name>:<seed> with name in "
                f"{', '.join(sorted(GENERATORS))})",
            )
    path = Path(name_or_path)
    source = str(name_or_path)
    if not path.exists():
        raise ScenarioError(source, "", "no such file")
    if not path.is_file():
        raise ScenarioError(source, "", "not a file")
    try:
        return source, path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(source, "", f"cannot read: {exc}") from None


def load_scenario(name_or_path: str | Path) -> Scenario:
    """Load a scenario by built-in name, ``<generator>:<seed>`` (``random-ch2:7``), or YAML path.

    Raises:
        ScenarioError: the file is missing, malformed, or describes an invalid scene.
    """
    if isinstance(name_or_path, str) and ":" in name_or_path and not Path(name_or_path).exists():
        name, _, seed_text = name_or_path.partition(":")
        if name in GENERATORS:
            if not seed_text.isdigit():
                raise ScenarioError(
                    name_or_path, "", f"expected {name}:<non-negative integer seed>"
                )
            return GENERATORS[name](int(seed_text))
    source, text = scenario_text(name_or_path)
    return scenario_from_dict(parse_yaml(text, source), source)
