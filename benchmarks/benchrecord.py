"""The one shape in which a benchmark records a judged target, read by ``summary.py``.

A benchmark puts a list of records under :data:`KEY` (``"records"``) in its JSON file; each
record is a dict:

* ``name``: the target's key (unique across the benchmarks, e.g. ``"vs_irsim_100"``);
* ``target``: the limit as text (``">= 150x"``, ``"<= 15 µs"``);
* ``measured``: the measured value (a number, or ``None`` when it was not measured) and ``unit``;
* ``limit``, ``direction`` (``"<="`` / ``">="``) and ``ratio`` = measured / limit;
* ``pass``: ``True`` / ``False``, ``None`` when not measured (then ``note`` says why);
* ``work``: one line saying what work each side does per step (or episode, or decision) when
  the figure compares two sides (a peer or an A/B ratio); empty for an absolute figure.
"""

from __future__ import annotations

import math
from typing import Any

#: the key of the list of records in a benchmark's JSON file
KEY = "records"


def limit_text(limit: float, direction: str, unit: str = "") -> str:
    """``">= 150x"``, ``"<= 15 µs"``: the limit as the table prints it."""
    number = f"{limit:,.0f}" if abs(limit) >= 1000 else f"{limit:g}"
    return f"{direction} {number}{unit}"


def record(
    name: str,
    measured: float | None,
    limit: float,
    direction: str,
    *,
    unit: str = "",
    work: str = "",
    note: str | None = None,
) -> dict[str, Any]:
    """A judged target: ``measured`` against ``limit`` in ``direction`` (``"<="`` or ``">="``).

    ``measured`` ``None`` (or not finite) reads "not measured": ``pass`` and ``ratio`` are
    ``None`` and ``note`` should say why.
    """
    if direction not in ("<=", ">="):
        raise ValueError(f"direction must be '<=' or '>=' (got {direction!r})")
    value = float(measured) if measured is not None and math.isfinite(measured) else None
    ok: bool | None = None
    if value is not None:
        ok = value <= limit if direction == "<=" else value >= limit
    out: dict[str, Any] = {
        "name": name,
        "target": limit_text(limit, direction, unit),
        "measured": value,
        "unit": unit,
        "limit": limit,
        "direction": direction,
        "ratio": value / limit if value is not None and limit else None,
        "pass": ok,
        "work": work,
    }
    if note is not None:
        out["note"] = note
    return out


def from_judged(
    name: str, judged: dict[str, Any], *, unit: str = "", work: str = ""
) -> dict[str, Any]:
    """A record from an older target dict (``measured``, ``limit``, ``direction``; ``note``)."""
    return record(
        name,
        judged.get("measured"),
        float(judged["limit"]),
        str(judged.get("direction", "<=")),
        unit=unit,
        work=work,
        note=judged.get("note"),
    )
