"""The report's first screen, "which law, where": regime map heat maps and the law x family table.

:func:`decision_view` reads a results store (never writes it) and returns what the report template
shows first:

* two heat maps over the regime grid of :mod:`uvnav.experiments.regime` — success and
  robot-driven collisions, one row per law, one panel per (vehicle limits, robot visible?,
  sensing), one column per (pedestrian speed / V_max, crowd density); a law not run in a cell
  (the holonomic laws on the acceleration-limited unicycle) leaves it blank — with each rate's
  95 % Wilson interval and sample size in its tooltip, a star on the laws the evidence cannot
  separate from the best;
* one generated recommendation per regime (:func:`uvnav.experiments.regime.recommend`);
* what sensing costs each law: its success with exact readings, noisy centres and a lidar
  alone on the same crowds (:func:`uvnav.experiments.regime.sensing_costs`);
* the law x scene-family table at equal seeds (:func:`uvnav.experiments.regime.family_table`),
  rates with intervals, small samples flagged.

The heat maps are plain HTML tables (coloured cells, the interval in each cell's tooltip): the
first screen needs no script and no plotly.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from uvnav.experiments.regime import (
    BEYOND_MARK,
    SMALL_SAMPLE,
    CellStats,
    FamilyCell,
    Rate,
    Regime,
    cell_stats,
    family_table,
    law_lines,
    ranking,
    recommend,
    sensing_costs,
)

#: the small-sample marker of the report (rates on fewer than SMALL_SAMPLE episodes)
SMALL_MARK = "⚠"


def _panel(c: Regime) -> tuple[bool, bool, bool, float]:
    """A cell's panel: the vehicle ideal or acceleration-limited, the robot visible or not,
    then its sensing."""
    return (c.limited, c.visible, c.lidar, c.noise)


def _panels(cells: Sequence[Regime]) -> list[tuple[bool, bool, bool, float]]:
    return sorted({_panel(c) for c in cells})


def _order(c: Regime) -> tuple[bool, bool, bool, float, float, int]:
    return (*_panel(c), c.speed_ratio, c.n_humans)


def _panel_title(limited: bool, visible: bool, lidar: bool, noise: float) -> str:
    seen = "visible robot" if visible else "invisible robot"
    panel = Regime(0, 0.0, visible, noise, lidar, limited)
    return f"{seen}, {panel.sensing}" + (f", {panel.vehicle}" if limited else "")


def _cell_colour(p: float, good: bool) -> str:
    """A rate's background on the red-yellow-green scale (green is good), as ``#rrggbb``.

    >>> _cell_colour(1.0, True), _cell_colour(1.0, False)
    ('#006837', '#a50026')
    """
    from matplotlib import colormaps
    from matplotlib.colors import to_hex

    cmap = colormaps["RdYlGn" if good else "RdYlGn_r"]
    return str(to_hex(cmap(min(max(p, 0.0), 1.0))))


def _cell(s: CellStats | None, law: str, c: Regime, metric: str, best: set[str]) -> dict[str, str]:
    """One heat-map cell: its text (rate in %, ★ when best), colours and tooltip."""
    if s is None:
        return {"text": "", "bg": "#ffffff", "fg": "#222", "title": f"{law}, {c.label}: not run"}
    r: Rate = getattr(s, metric)
    lo, hi = r.interval
    mark = "★" if law in best else ""
    title = (
        f"{law}{BEYOND_MARK if s.beyond else ''}, {c.label}: {metric.replace('_', '-')} "
        f"{100 * r.p:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}], n={r.n}"
        + (f" {SMALL_MARK} small sample" if r.small else "")
        + ("; ★ best or not separable from it" if mark else "")
    )
    # dark cells at both ends of the scale carry white text
    fg = "#fff" if abs(r.p - 0.5) > 0.35 else "#222"
    return {"text": f"{100 * r.p:.0f}{mark}", "bg": _cell_colour(r.p, metric == "success"),
            "fg": fg, "title": title}  # fmt: skip


def regime_heatmap(
    stats: dict[Regime, list[CellStats]], metric: str, *, div_id: str
) -> dict[str, Any]:
    """One heat map (``metric``: ``"success"`` or ``"robot_collision"``) as a table the report
    draws with no script: ``{"id", "title", "panels": [{"title", "columns"}], "rows": [{"law",
    "cells": [{"text", "bg", "fg", "title", "edge"}]}]}``: one row per law, one column group per
    panel (vehicle limits, robot visible or not, sensing; ``edge`` marks a panel's first
    column), one column per (pedestrian speed / V_max, density); a cell is the rate in %, its
    tooltip the 95 % Wilson interval and n."""
    cells = sorted(stats, key=_order)
    laws = sorted({s.law for v in stats.values() for s in v})
    best = {c: {b.law for b in ranking(stats[c])[0]} for c in cells}
    panels = [
        {
            "title": _panel_title(*p),
            "columns": [f"v{c.speed_ratio:g}·n{c.n_humans}" for c in cells if _panel(c) == p],
        }
        for p in _panels(cells)
    ]
    edges = {i for i, c in enumerate(cells) if i == 0 or _panel(c) != _panel(cells[i - 1])}
    rows = [
        {
            "law": law,
            "cells": [
                _cell(next((x for x in stats[c] if x.law == law), None), law, c, metric, best[c])
                | {"edge": i in edges}
                for i, c in enumerate(cells)
            ],
        }
        for law in laws
    ]
    title = "success rate" if metric == "success" else "robot-driven collision rate"
    return {
        "id": div_id,
        "title": f"{title} [%] per law and regime",
        "panels": panels,
        "rows": rows,
    }


def _rate_cell(r: Rate) -> str:
    lo, hi = r.interval
    return f"{r.p:.2f} [{lo:.2f}, {hi:.2f}]"


def family_view(cells: Sequence[FamilyCell]) -> dict[str, Any]:
    """The law x family table: ``{"families": [{"name", "n", "small", "note"}], "rows":
    [{"law", "cells": [{"success", "collision", "beyond"} | None]}]}``."""
    families = sorted({c.family for c in cells})
    laws = sorted({c.law for c in cells})
    fam_rows = []
    for f in families:
        here = [c for c in cells if c.family == f]
        n = min(c.success.n for c in here)
        more = sorted({c.ran for c in here if c.ran > n})
        note = (
            f"some laws ran up to {more[-1]} scenes; all are shown on the {n} every law ran"
            if more
            else ""
        )
        fam_rows.append({"name": f, "n": n, "small": n < SMALL_SAMPLE, "note": note})
    rows = []
    for law in laws:
        row = []
        for f in families:
            c = next((x for x in cells if x.family == f and x.law == law), None)
            row.append(
                None
                if c is None
                else {
                    "success": _rate_cell(c.success),
                    "collision": _rate_cell(c.collision),
                    "beyond": c.beyond,
                }
            )
        rows.append({"law": law, "cells": row})
    return {"families": fam_rows, "rows": rows}


def decision_view(db_path: Path) -> dict[str, Any]:
    """Everything the first screen shows, read from the store (empty parts when not stored),
    with "which law, where" in a few lines (``law_lines``, :func:`uvnav.experiments.regime.
    law_lines`) for the report's summary."""
    from uvnav.bench.store import ResultsStore

    with ResultsStore(Path(db_path), readonly=True) as store:
        stats = cell_stats(store)
        fams = family_table(store)
    out: dict[str, Any] = {
        "heatmaps": [], "recommendations": [], "cells": [], "families": None, "sensing_costs": [],
        "law_lines": [],
    }  # fmt: skip
    if stats:
        out["law_lines"] = law_lines(stats)
        out["heatmaps"] = [
            regime_heatmap(stats, "success", div_id="regime-success"),
            regime_heatmap(stats, "robot_collision", div_id="regime-collision"),
        ]
        order = sorted(stats, key=_order)
        seeds = sorted({s.success.n for v in stats.values() for s in v})
        out["seeds"] = seeds
        out["small"] = seeds[0] < SMALL_SAMPLE
        out["n_cells"] = len(order)
        out["laws"] = sorted({s.law for v in stats.values() for s in v})
        for c in order:
            best, _ = ranking(stats[c])
            out["recommendations"].append(
                {
                    "regime": c.label,
                    "best": ", ".join(b.law + (BEYOND_MARK if b.beyond else "") for b in best),
                    "text": recommend(c.label, stats[c]).split(": ", 1)[1],
                }
            )
            for s in stats[c]:
                out["cells"].append(
                    {
                        "regime": c.label,
                        "law": s.law + (BEYOND_MARK if s.beyond else ""),
                        "n": s.success.n,
                        "small": s.success.small,
                        "success": _rate_cell(s.success),
                        "robot_collision": _rate_cell(s.robot_collision),
                        "collision": _rate_cell(s.collision),
                    }
                )
        out["sensing_costs"] = [
            {
                "law": c.law,
                "exact": _rate_cell(c.exact),
                "noisy": _rate_cell(c.noisy),
                "lidar": _rate_cell(c.lidar),
                "cost": f"{100 * c.lidar_cost:+.0f}",
                "n": c.lidar.n,
            }
            for c in sensing_costs(stats)
        ]
    if fams:
        out["families"] = family_view(fams)
    return out


__all__ = ["SMALL_MARK", "decision_view", "family_view", "regime_heatmap"]
