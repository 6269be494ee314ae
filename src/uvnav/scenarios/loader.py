"""Reading and writing scenario files, and the built-in scenario library.

A scenario is named either by a path to a YAML file or by the name of a built-in (the YAML files
shipped in ``uvnav/scenarios/builtin/``, thesis experiments first), or by a generator spec
``random-ch2:<seed>`` (see :func:`uvnav.scenarios.generators.random_ch2_scenario`).  Every
problem is raised as a one-line :class:`~uvnav.scenarios.errors.ScenarioError`.

YAML is read with ``yaml.SafeLoader`` extended to reject duplicate keys (PyYAML silently keeps the
last one, which hides typos such as two ``speed:`` lines).
"""

from __future__ import annotations

import re
import types
import typing
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from uvnav.scenarios.errors import ScenarioError, from_validation_error
from uvnav.scenarios.schema import MOTION_TYPES, Scenario

BUILTIN_PACKAGE = "uvnav.scenarios"
BUILTIN_DIR = "builtin"


def _generator_names() -> list[str]:
    from uvnav.scenarios.generators import GENERATORS

    return list(GENERATORS)


class _UniqueKeyLoader(yaml.SafeLoader):
    """SafeLoader that raises on duplicate mapping keys."""


def _construct_unique_mapping(
    loader: yaml.SafeLoader, node: yaml.MappingNode, deep: bool = False
) -> Any:
    seen: set[Any] = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r}", key_node.start_mark
            )
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_unique_mapping
)
# YAML 1.2's exponent numbers without a dot (1e3, -2E-4), which YAML 1.1 reads as text
_UniqueKeyLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?[0-9]+[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def yaml_value(text: str) -> Any:
    """One YAML value, read as the scenario and campaign files are (``1e3`` is a number).

    >>> yaml_value("1e3"), yaml_value("[1, -2E-1]"), yaml_value("1.5"), yaml_value("e3")
    (1000.0, [1, -0.2], 1.5, 'e3')

    Raises:
        yaml.YAMLError: malformed YAML, and also a value Python cannot hold (an integer of more
            than 4,300 digits, nesting deeper than the interpreter's recursion limit).
    """
    try:
        return yaml.load(text, Loader=_UniqueKeyLoader)
    except (ValueError, RecursionError) as exc:
        raise yaml.YAMLError(_unholdable(exc)) from None


def _unholdable(exc: ValueError | RecursionError) -> str:
    """Why YAML that parsed cannot be held: nested too deep, or a number too long."""
    if isinstance(exc, RecursionError):
        return "nested too deeply"
    return "a number too long to read (more than 4,300 digits)"


def parse_yaml(
    text: str,
    source: str,
    *,
    kind: str = "scenario",
    error: type[ScenarioError] = ScenarioError,
) -> dict[str, Any]:
    """Parse YAML text (duplicate keys rejected) into a mapping.

    Args:
        text: the YAML document.
        source: file name for messages.
        kind: what the document describes, for messages ("scenario", "campaign").
        error: the :class:`ScenarioError` subclass to raise.

    Raises:
        ScenarioError: malformed YAML (with its line number) or a top level that is not a mapping.
    """
    try:
        data = yaml.load(text, Loader=_UniqueKeyLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}" if mark is not None else ""
        what = exc.problem or exc.context or "cannot parse"
        raise error(source, where, f"malformed YAML: {what}") from None
    except yaml.YAMLError as exc:
        raise error(source, "", f"malformed YAML: {exc}") from None
    except (ValueError, RecursionError) as exc:
        raise error(source, "", f"malformed YAML: {_unholdable(exc)}") from None
    if data is None:
        raise error(source, "", f"empty file (expected a {kind} mapping)")
    if not isinstance(data, dict):
        raise error(
            source, "<root>", f"expected a mapping of {kind} fields (got {type(data).__name__})"
        )
    return data


def _unwrap(tp: Any) -> Any:
    """Strip ``Annotated`` and ``Optional`` from a type annotation."""
    while True:
        origin = typing.get_origin(tp)
        if origin is typing.Annotated:
            tp = typing.get_args(tp)[0]
            continue
        if origin in (typing.Union, types.UnionType):
            args = [a for a in typing.get_args(tp) if a is not type(None)]
            if len(args) == 1:
                tp = args[0]
                continue
        return tp


def allowed_fields(loc: tuple[str | int, ...]) -> list[str] | None:
    """Field names allowed at pydantic location ``loc`` of a :class:`Scenario`, if resolvable."""
    current: Any = Scenario
    for part in loc:
        current = _unwrap(current)
        if isinstance(part, int):
            if typing.get_origin(current) in (list, tuple):
                current = typing.get_args(current)[0]
                continue
            return None
        if (
            isinstance(current, type)
            and issubclass(current, BaseModel)
            and part in current.model_fields
        ):
            current = current.model_fields[part].annotation
            continue
        if part in MOTION_TYPES:
            current = MOTION_TYPES[part]
            continue
        return None
    current = _unwrap(current)
    if isinstance(current, type) and issubclass(current, BaseModel):
        return list(current.model_fields)
    return None


def scenario_from_dict(data: dict[str, Any], source: str = "<dict>") -> Scenario:
    """Validate a mapping as a :class:`Scenario`.

    Args:
        data: the parsed YAML (or any mapping of scenario fields).
        source: what to call the origin in error messages (a file name); when it is an existing
            file, relative ``crowd.dataset`` paths are taken from its folder.

    Raises:
        ScenarioError: one line naming ``source``, the field path and the problem.
    """
    if not isinstance(data, dict):
        raise ScenarioError(
            source, "<root>", f"expected a mapping of scenario fields (got {type(data).__name__})"
        )
    if data.get("dim") == 3:  # 3D scenes (thesis Ch. 3): their own schema
        from uvnav.scenarios.schema3d import scenario3d_from_dict

        return scenario3d_from_dict(data, source)  # type: ignore[return-value]
    base = Path(source).parent if Path(source).is_file() else None
    try:
        scenario = Scenario.model_validate(data, context={"base_dir": base})
    except ValidationError as exc:
        raise from_validation_error(
            exc, source, tags=tuple(MOTION_TYPES), allowed_fields=allowed_fields
        ) from None
    scenario._source = source
    return scenario


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
                f"{', '.join(sorted(_generator_names()))})",
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
        from uvnav.scenarios.generators import GENERATORS

        name, _, seed_text = name_or_path.partition(":")
        if name in GENERATORS:
            if not seed_text.isdigit():
                raise ScenarioError(
                    name_or_path, "", f"expected {name}:<non-negative integer seed>"
                )
            return GENERATORS[name](int(seed_text))
    source, text = scenario_text(name_or_path)
    return scenario_from_dict(parse_yaml(text, source), source)


class _FlowListDumper(yaml.SafeDumper):
    """Dumper writing lists of scalars (and lists of points) in flow style: ``[0.0, 1.0]``."""


def _represent_list(dumper: yaml.SafeDumper, data: list[Any]) -> yaml.Node:
    flow = all(not isinstance(x, dict) for x in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


_FlowListDumper.add_representer(list, _represent_list)


def scenario_to_dict(scenario: Scenario) -> dict[str, Any]:
    """Plain JSON/YAML-able mapping of ``scenario`` (``None`` fields left out)."""
    return scenario.model_dump(mode="json", exclude_none=True)


def scenario_to_yaml(scenario: Scenario) -> str:
    """YAML text that :func:`scenario_from_dict` reads back into an equal :class:`Scenario`."""
    return yaml.dump(
        scenario_to_dict(scenario),
        Dumper=_FlowListDumper,
        sort_keys=False,
        allow_unicode=True,
        width=100,
    )
