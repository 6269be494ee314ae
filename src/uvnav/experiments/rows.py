"""Rows of the "thesis reported vs uvnav measured" table and the figures written in them: one
place for the row dict and the rate-with-interval text every experiment writes.  Imports no
experiment, so every experiment and :mod:`uvnav.experiments.sections` can use it."""

from __future__ import annotations

from typing import Any

from uvnav.bench.summary import wilson_interval


def table_row(
    quantity: str, thesis: str, measured: str, note: str | None = None, **extra: Any
) -> dict[str, Any]:
    """One row of the table; ``extra``: further columns (``verdict``: an experiment's own
    verdict, :mod:`uvnav.experiments.verdict`)."""
    out = {"quantity": quantity, "thesis": thesis, "measured": measured}
    return {**out, **({} if note is None else {"note": note}), **extra}


def rate_text(k: int, n: int, spec: str = ".2f") -> str:
    """``k / n`` and its 95 % Wilson interval, each formatted with ``spec``:
    ``"0.43 [0.34, 0.53]"`` (``".0%"``: ``"43% [34%, 53%]"``); a rate of 0 for ``n = 0``.

    >>> rate_text(43, 100)
    '0.43 [0.34, 0.53]'
    """
    lo, hi = wilson_interval(k, n)
    return f"{k / n if n else 0.0:{spec}} [{lo:{spec}}, {hi:{spec}}]"


def m_text(x: Any, digits: int = 2) -> str:
    """A length [m] as ``"1.23 m"``; ``"n/a"`` for a missing or non-finite value."""
    import math

    if x is None or not math.isfinite(float(x)):
        return "n/a"
    return f"{float(x):.{digits}f} m"
