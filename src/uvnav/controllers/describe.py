"""What a law's parameters say about themselves, for the people who set them: each field's
description from its class's ``Attributes:`` docstring section, its type and that description
as a user reads them (the ``controllers show`` table, the ROS 2 node's parameter list)."""

from __future__ import annotations

import dataclasses
import inspect
import re
from dataclasses import dataclass
from typing import Any


def attribute_docs(cls: type) -> dict[str, str]:
    """Field descriptions from the ``Attributes:`` sections of a Google-style class docstring
    and of its bases' (a subclass's entry wins over its base's)."""
    out: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        out.update(_section_docs(inspect.cleandoc(klass.__dict__.get("__doc__") or "")))
    return out


def _section_docs(doc: str) -> dict[str, str]:
    """The entries of the ``Attributes:`` (``Args:``, ``Parameters:``) sections of ``doc``."""
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


def plain_type(annotation: str) -> str:
    """A parameter's type as a user reads it: ``Literal['a', 'b']`` is ``a | b``.

    >>> plain_type("Literal['side', 'min_beta']"), plain_type("float | None")
    ('side | min_beta', 'float | None')
    """
    m = re.fullmatch(r"Literal\[(.*)\]", annotation.strip())
    if m is None:
        return annotation
    return " | ".join(v.strip().strip("'\"") for v in m.group(1).split(","))


def plain_doc(doc: str) -> str:
    """A docstring line without reStructuredText markup: ````x```` and :role:`~a.b.x` read
    ``x``.

    >>> plain_doc('``"side"`` (see :func:`~uvnav.geometry.tangents.tangent_points`)')
    '"side" (see tangent_points)'
    """
    doc = re.sub(r":\w+:`~?(?:[\w.]*\.)?([^`]+)`", r"\1", doc)
    return doc.replace("``", "")


@dataclass(frozen=True)
class ParamField:
    """One field of a law's parameter dataclass: its name, its annotation as written, its
    default (``None`` without one) and its description (the ``Attributes:`` entry)."""

    name: str
    annotation: Any
    default: Any
    doc: str


def param_fields(params_type: type | None) -> list[ParamField]:
    """The fields of a law's parameter dataclass in declaration order (none for ``None`` or a
    type that is not a dataclass)."""
    if params_type is None or not dataclasses.is_dataclass(params_type):
        return []
    docs = attribute_docs(params_type)
    out = []
    for f in dataclasses.fields(params_type):
        if f.default is not dataclasses.MISSING:
            default: Any = f.default
        elif f.default_factory is not dataclasses.MISSING:
            default = f.default_factory()
        else:
            default = None
        out.append(ParamField(f.name, f.type, default, docs.get(f.name, "")))
    return out
