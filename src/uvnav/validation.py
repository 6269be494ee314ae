"""Pydantic's validation errors in uvnav's words: one short line per problem.

Scenario files (:mod:`uvnav.scenarios.errors`) and law parameters
(:func:`uvnav.controllers.base.build_params`) are both checked by pydantic; both report a
problem through :func:`describe_error`, so that a wrong value reads the same wherever it is
given (``must be > 0 (got -1)``, ``expected a number (got 'abc')``).  Layer 0: pydantic only.

>>> from pydantic import TypeAdapter, ValidationError
>>> try:
...     TypeAdapter(int).validate_python("abc")
... except ValidationError as exc:
...     describe_error(exc.errors()[0], None)
"expected an integer (got 'abc')"
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any


def one_line(text: str) -> str:
    """``text`` with every run of white space, line breaks included, as one space."""
    return re.sub(r"\s+", " ", str(text)).strip()


def clip(text: str, limit: int) -> str:
    """``text``, cut to ``limit`` characters ending in ``...`` when longer.

    >>> clip("abcdef", 5), clip("abc", 5)
    ('ab...', 'abc')
    """
    return text if len(text) <= limit else text[: limit - 3] + "..."


def show_value(value: Any, limit: int = 40) -> str:
    """Compact rendering of an offending input value (``0.0`` as ``0``, strings quoted)."""
    if isinstance(value, float) and value.is_integer():
        text = str(int(value))
    elif isinstance(value, str):
        text = repr(value)
    elif isinstance(value, dict):
        text = "{" + ", ".join(str(k) for k in value) + "}"
    else:
        text = repr(value)
    return clip(one_line(text), limit)


#: pydantic error types about the kind of value, and the noun we expect instead
TYPE_NOUNS = {
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "an integer",
    "int_parsing": "an integer",
    "int_from_float": "an integer",
    "bool_type": "true or false",
    "bool_parsing": "true or false",
    "string_type": "a string",
    "dict_type": "a mapping",
    "model_type": "a mapping",
    "model_attributes_type": "a mapping",
    "list_type": "a list",
    "tuple_type": "a list",
    "finite_number": "a finite number",
}


def describe_error(err: Any, allowed: Sequence[str] | None) -> str:
    """Translate one pydantic error dict into a short problem statement."""
    kind = err.get("type", "")
    ctx = err.get("ctx") or {}
    value = err.get("input")
    if kind == "value_error" and isinstance(ctx.get("error"), Exception):
        return str(ctx["error"])
    bounds = {
        "greater_than": ">",
        "greater_than_equal": ">=",
        "less_than": "<",
        "less_than_equal": "<=",
    }
    if kind in bounds:
        key = {
            "greater_than": "gt",
            "greater_than_equal": "ge",
            "less_than": "lt",
            "less_than_equal": "le",
        }[kind]
        return f"must be {bounds[kind]} {show_value(ctx.get(key))} (got {show_value(value)})"
    if kind == "missing":
        return "required field is missing"
    if kind == "extra_forbidden":
        hint = f" (allowed: {', '.join(allowed)})" if allowed else ""
        return f"unknown field{hint}"
    if kind in TYPE_NOUNS:
        return f"expected {TYPE_NOUNS[kind]} (got {show_value(value)})"
    if kind == "literal_error":
        return f"must be {ctx.get('expected')} (got {show_value(value)})"
    if kind in ("too_short", "too_long"):
        n = ctx.get("actual_length")
        limit = ctx.get("min_length") if kind == "too_short" else ctx.get("max_length")
        word = "at least" if kind == "too_short" else "at most"
        return f"needs {word} {limit} item(s) (got {n})"
    if kind == "union_tag_invalid":
        what = ctx.get("discriminator", "tag")
        expected = ctx.get("expected_tags")
        return f"unknown {what} {show_value(ctx.get('tag'))} (expected one of: {expected})"
    if kind == "union_tag_not_found":
        return f"missing {ctx.get('discriminator', 'tag')} (one of the motion types)"
    msg = str(err.get("msg", "invalid value"))
    return (
        f"{msg} (got {show_value(value)})"
        if value is not None and not isinstance(value, dict)
        else msg
    )
