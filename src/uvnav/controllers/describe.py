"""What a law's parameters say about themselves, for the people who set them: each field's
description from its class's ``Attributes:`` docstring section, its type and that description
as a user reads them (the ``controllers show`` table, the ROS 2 node's parameter list)."""

from __future__ import annotations

import inspect
import re


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
