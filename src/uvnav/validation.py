"""Pydantic's validation errors in uvnav's words: one short line per problem.

Scenario files (:mod:`uvnav.scenarios.errors`) and law parameters
(:func:`uvnav.controllers.base.build_params`) are both checked by pydantic; both report a
problem through :func:`describe_error`, so that a wrong value reads the same wherever it is
given (``must be > 0 (got -1)``, ``expected a number (got 'abc')``).  Layer 0: pydantic only
(numpy imported by the array readers when they are called).

Also the shared bounds of what a file may hold: :data:`MAX_COORDINATE`, the largest coordinate
magnitude [m] of a scene, a pedestrian track or a terrain, and :func:`load_npy` /
:func:`load_npz`, which read an array file only after its header's shape has been checked
against a size limit and against the bytes the file holds (a header claiming 10^6 x 10^6
values is one line, not a ``MemoryError``).

>>> from pydantic import TypeAdapter, ValidationError
>>> try:
...     TypeAdapter(int).validate_python("abc")
... except ValidationError as exc:
...     describe_error(exc.errors()[0], None)
"expected an integer (got 'abc')"
"""

from __future__ import annotations

import math
import re
import zipfile
from collections.abc import Sequence
from pathlib import Path
from typing import IO, Any

#: Largest magnitude [m] of a coordinate (and of a terrain height) read from a file: 1000 km,
#: far beyond any scene uvnav models, and small enough that squared distances and areas stay
#: exact to well below a millimetre in float64.  Beyond it a number is a mistake, not a place.
MAX_COORDINATE = 1e6


def coordinate_problem(value: float) -> str | None:
    """Why ``value`` is not a usable coordinate [m] (one line), or ``None``.

    >>> coordinate_problem(3.5) is None, coordinate_problem(1e15)
    (True, '1e+15 is outside the modelled range |x| <= 1e+06 m')
    """
    if not math.isfinite(value):
        return f"{value} is not a finite number"
    if abs(value) > MAX_COORDINATE:
        return f"{value:g} is outside the modelled range |x| <= {MAX_COORDINATE:g} m"
    return None


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


def _npy_header(fh: IO[bytes], name: str) -> tuple[tuple[int, ...], Any, int]:
    """Shape, dtype and header length of the ``.npy`` stream ``fh`` (positioned at its start)."""
    from numpy.lib import format as npformat

    start = fh.tell()
    try:
        version = npformat.read_magic(fh)
        reader = {
            (1, 0): npformat.read_array_header_1_0,
            (2, 0): npformat.read_array_header_2_0,
        }.get(version)
        if reader is None:
            raise ValueError(f"unsupported .npy format version {version}")
        shape, _fortran, dtype = reader(fh)
    except (ValueError, SyntaxError, EOFError) as exc:
        raise ValueError(
            f"{name}: not a .npy array ({one_line(str(exc)) or 'bad header'})"
        ) from None
    return tuple(int(n) for n in shape), dtype, fh.tell() - start


def _check_claim(
    shape: tuple[int, ...], dtype: Any, data_bytes: int, limit: int, name: str
) -> None:
    """Refuse a header whose shape has more than ``limit`` values or more bytes than follow it."""
    n = math.prod(shape)
    if n > limit:
        raise ValueError(
            f"{name}: the header claims shape {shape} = {n:.3g} values, more than the limit "
            f"of {limit:.3g}"
        )
    need = n * int(dtype.itemsize)
    if need > data_bytes:
        raise ValueError(
            f"{name}: the header claims shape {shape} ({need} bytes) but only {data_bytes} "
            "bytes follow it (truncated or forged file)"
        )


def load_npy(path: str | Path, limit: int) -> Any:
    """The array of the ``.npy`` file ``path``, read only when its header's shape has at most
    ``limit`` values and the file holds its bytes; pickled objects are never loaded.

    Raises:
        ValueError: one line naming the problem (the caller names the file).
        OSError: the file cannot be read.
    """
    import numpy as np

    p = Path(path)
    with p.open("rb") as fh:
        shape, dtype, header = _npy_header(fh, "array")
        _check_claim(shape, dtype, p.stat().st_size - header, limit, "array")
        fh.seek(0)
        return np.lib.format.read_array(fh, allow_pickle=False)


def load_npz(path: str | Path, limit: int) -> dict[str, Any]:
    """The arrays of the ``.npz`` archive ``path`` by name, each read only when its header's
    shape has at most ``limit`` values and the archive holds its bytes.

    Raises:
        ValueError: one line naming the array and the problem (the caller names the file).
        OSError, zipfile.BadZipFile: the file cannot be read as a zip archive.
    """
    import numpy as np

    out: dict[str, Any] = {}
    with zipfile.ZipFile(path) as zf:
        for info in zf.infolist():
            key = info.filename.removesuffix(".npy")
            name = f"array {key!r}"
            with zf.open(info) as fh:
                shape, dtype, header = _npy_header(fh, name)
                _check_claim(shape, dtype, info.file_size - header, limit, name)
            with zf.open(info) as fh:
                out[key] = np.lib.format.read_array(fh, allow_pickle=False)
    return out
