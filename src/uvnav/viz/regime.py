"""The report's first screen, "which law, where": regime map heat maps and the law x family table.

:func:`decision_view` reads a results store (never writes it) and returns what the report template
shows first:

* two plotly heat maps over the regime grid of :mod:`uvnav.experiments.regime` — success and
  robot-driven collisions, one row per law, one panel per (robot visible?, sensing) pair, one
  column per (pedestrian speed / V_max, crowd density) — with each rate's 95 % Wilson interval
  and sample size on hover, a star on the laws the evidence cannot separate from the best;
* one generated recommendation per regime (:func:`uvnav.experiments.regime.recommend`);
* what sensing costs each law: its success with exact readings, noisy centres and a lidar
  alone on the same crowds (:func:`uvnav.experiments.regime.sensing_costs`);
* the law x scene-family table at equal seeds (:func:`uvnav.experiments.regime.family_table`),
  rates with intervals, small samples flagged.

The figures are ``<div>`` fragments that use the report's ``plotly.min.js``.
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
    ranking,
    recommend,
    sensing_costs,
)

#: the small-sample marker of the report (rates on fewer than SMALL_SAMPLE episodes)
SMALL_MARK = "⚠"


def _panel(c: Regime) -> tuple[bool, bool, float]:
    """A cell's panel: the robot visible or not, then its sensing."""
    return (c.visible, c.lidar, c.noise)


def _panels(cells: Sequence[Regime]) -> list[tuple[bool, bool, float]]:
    return sorted({_panel(c) for c in cells})


def _order(c: Regime) -> tuple[bool, bool, float, float, int]:
    return (*_panel(c), c.speed_ratio, c.n_humans)


def _panel_title(visible: bool, lidar: bool, noise: float) -> str:
    seen = "visible robot" if visible else "invisible robot"
    return f"{seen}, {Regime(0, 0.0, visible, noise, lidar).sensing}"


def regime_heatmap(stats: dict[Regime, list[CellStats]], metric: str, *, div_id: str) -> str:
    """One heat map (``metric``: ``"success"`` or ``"robot_collision"``) as an HTML fragment."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    cells = sorted(stats, key=_order)
    laws = sorted({s.law for v in stats.values() for s in v})
    panels = _panels(cells)
    fig = make_subplots(
        rows=1,
        cols=len(panels),
        shared_yaxes=True,
        horizontal_spacing=0.015,
        subplot_titles=[_panel_title(*p) for p in panels],
    )
    good = metric == "success"
    for col, panel in enumerate(panels, start=1):
        here = [c for c in cells if _panel(c) == panel]
        xs = [f"v{c.speed_ratio:g}·n{c.n_humans}" for c in here]
        z: list[list[float | None]] = []
        text: list[list[str]] = []
        hover: list[list[str]] = []
        for law in laws:
            zr: list[float | None] = []
            tr: list[str] = []
            hr: list[str] = []
            for c in here:
                s = next((x for x in stats[c] if x.law == law), None)
                if s is None:
                    zr.append(None)
                    tr.append("")
                    hr.append(f"{law}<br>{c.label}<br>not run")
                    continue
                best = {b.law for b in ranking(stats[c])[0]}
                r: Rate = getattr(s, metric)
                zr.append(r.p)
                mark = "★" if law in best else ""
                tr.append(f"{r.p * 100:.0f}{mark}")
                lo, hi = r.interval
                hr.append(
                    f"{law}{BEYOND_MARK if s.beyond else ''}<br>{c.label}<br>"
                    f"{metric.replace('_', '-')} {r.p:.2f} [{lo:.2f}, {hi:.2f}], n={r.n}"
                    + (f" {SMALL_MARK} small sample" if r.small else "")
                    + ("<br>★ best or not separable from it" if mark else "")
                )
            z.append(zr)
            text.append(tr)
            hover.append(hr)
        fig.add_trace(
            go.Heatmap(
                z=z,
                x=xs,
                y=laws,
                text=text,
                texttemplate="%{text}",
                textfont={"size": 11},
                customdata=hover,
                hovertemplate="%{customdata}<extra></extra>",
                zmin=0,
                zmax=1,
                colorscale="RdYlGn" if good else "RdYlGn_r",
                showscale=col == len(panels),
                colorbar={"title": {"text": "rate"}, "len": 0.9, "thickness": 12},
                xgap=1,
                ygap=1,
            ),
            row=1,
            col=col,
        )
    fig.update_xaxes(tickangle=-60, tickfont={"size": 10})
    fig.update_yaxes(tickfont={"size": 11}, autorange="reversed")
    fig.update_annotations(font={"size": 12})
    title = "success rate" if good else "robot-driven collision rate"
    fig.update_layout(
        title={"text": f"{title} [%] per law and regime", "font": {"size": 14}, "x": 0},
        height=150 + 24 * len(laws),
        margin={"l": 10, "r": 10, "t": 60, "b": 70},
    )
    html: str = fig.to_html(
        full_html=False,
        include_plotlyjs=False,
        div_id=div_id,
        config={"responsive": True, "displaylogo": False},
    )
    return html


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
    """Everything the first screen shows, read from the store (empty parts when not stored)."""
    from uvnav.bench.store import ResultsStore

    with ResultsStore(Path(db_path), readonly=True) as store:
        stats = cell_stats(store)
        fams = family_table(store)
    out: dict[str, Any] = {
        "heatmaps": [], "recommendations": [], "cells": [], "families": None, "sensing_costs": [],
    }  # fmt: skip
    if stats:
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
