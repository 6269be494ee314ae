"""Figures and report of ``uvnav run`` (the renderers the CLI injects into
:func:`uvnav.experiments.run_all`).

:func:`render_reproduction` draws the Chapter 2 figures into ``report_dir/ch2`` — for each
recorded thesis-scene episode a :func:`~uvnav.viz.figures.plot_episode` figure (Figs. 2.7–2.9
style), the Fig. 2.10 comparison of all controllers on the comparison scene, a summary figure of
the random campaign — adds them to the Chapter 2 section, then writes the page with
:func:`~uvnav.viz.report.write_report` (one section per chapter).  The episode setups (start, goal,
vehicle limits) are rebuilt from the scenario with the stored seed; the trajectories are read from
the database.

:func:`chapter_renderers` gives the other chapters' figure renderers
(:class:`uvnav.experiments.sections.ChapterRenderers`) the CLI injects into the experiments.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from uvnav.bench.store import ResultsStore
from uvnav.experiments.ch2 import RenderRequest, RenderResult
from uvnav.experiments.sections import ChapterRenderers, ChapterSection, SectionFile
from uvnav.sim import EpisodeResult, EpisodeSetup
from uvnav.viz.figures import plot_campaign_summary, plot_comparison, plot_episode
from uvnav.viz.report import write_report

_LABELS = {
    "zhang2019-v1": "zhang2019-v1 (thesis law)",
    "savkin-wang2013-v1": "savkin-wang2013-v1 (baseline)",
}


def render_reproduction(req: RenderRequest) -> RenderResult:
    """Draw the reproduction's figures into ``req.report_dir`` and write ``index.html`` there.

    Args:
        req: what was run and where it is stored.

    Returns:
        The report path and the figure files (in report order).
    """
    import uvnav.scenarios as scenarios

    report_dir = Path(req.report_dir)
    out_dir = report_dir / "ch2"
    out_dir.mkdir(parents=True, exist_ok=True)
    figures: list[tuple[Path, str]] = []
    by_scene: dict[str, dict[str, tuple[EpisodeResult, EpisodeSetup]]] = {}
    with ResultsStore(req.db_path) as store:
        for ep in req.scene_episodes:
            if ep.status == "error":
                continue
            result = store.episode_result(ep.episode_id)
            if result.trajectory is None:
                continue
            scenario = scenarios.load_scenario(ep.scene)
            setup = scenarios.build_episode(scenario, ep.seed)
            path = out_dir / f"{ep.scene}--{ep.controller}.png"
            desc = getattr(scenario, "description", "") or ""
            plot_episode(result, setup, path, title=f"{ep.scene} — {ep.controller}")
            figures.append(
                (path, f"{ep.scene} with {ep.controller} (seed {ep.seed}). {desc}".strip())
            )
            by_scene.setdefault(ep.scene, {})[ep.controller] = (result, setup)
        random_df = store.episodes_frame(req.random_campaign)

    if req.comparison_scene and len(by_scene.get(req.comparison_scene, {})) >= 2:
        runs = by_scene[req.comparison_scene]
        order = sorted(runs, key=lambda c: (c != "savkin-wang2013-v1", c))  # Fig. 2.10: (a) Savkin
        path = out_dir / f"{req.comparison_scene}--comparison.png"
        plot_comparison(
            {_LABELS.get(c, c): runs[c] for c in order},
            path,
            title="Fig. 2.10: comparison of the two laws (one disc at constant velocity)",
        )
        first = next(
            (
                i
                for i, (p, _) in enumerate(figures)
                if p.name.startswith(f"{req.comparison_scene}--")
            ),
            len(figures),
        )
        figures.insert(
            first,
            (
                path,
                "Fig. 2.10 reproduced: paths of both laws on the comparison scene "
                "and their path lengths over time (thesis: 15.7 m Savkin–Wang, "
                "14.9 m Zhang).",
            ),
        )
    if not random_df.empty:
        path = out_dir / f"{req.random_campaign}-summary.png"
        plot_campaign_summary(
            random_df, path, title=f"Random Ch. 2 campaign ({random_df['seed'].nunique()} seeds)"
        )
        figures.append(
            (path, "Random campaign: outcomes, minimum clearance and detour ratio per law.")
        )
    sections = list(req.sections)
    ch2 = next((s for s in sections if s.key == "ch2"), None)
    loose: list[tuple[Path, str]] = []
    if ch2 is not None:
        ch2.figures = [SectionFile(p, c) for p, c in figures] + ch2.figures
    else:
        loose = figures
    report = write_report(
        req.db_path,
        report_dir,
        figures=loose,
        sections=sections,
        table=req.table,
        title="uvnav — reproduction of the thesis's experiments",
        summary_figure=False,
    )
    root = report_dir.resolve()
    files = [p for p, _ in figures] + [  # the other sections' files drawn into the report
        f.path
        for s in sections
        if s.key != "ch2"
        for f in (*s.figures, *s.links)
        if f.path.resolve().is_relative_to(root)
    ]
    return RenderResult(report_path=report, figures=files)


def render_ch7_plan(plan: Any, prefix: Path) -> list[Path]:
    """One Chapter 7 plan for the report: the Fig. 7.4-style PNG at ``<prefix>-fig7_4.png`` and the
    interactive 3D view at ``<prefix>-3d.html``, which loads the report's shared
    ``plotly.min.js`` (written one folder up, next to ``index.html``) instead of embedding its own
    copy (about 3.5 MB per plan)."""
    from uvnav.viz.figures_ch7 import plot_fig7_4, recon_3d_figure
    from uvnav.viz.interactive import PLOTLY_JS, write_plotly_js

    p = Path(prefix)
    p.parent.mkdir(parents=True, exist_ok=True)
    png = p.parent / f"{p.name}-fig7_4.png"
    plot_fig7_4(plan, png)
    write_plotly_js(p.parent.parent)
    html = p.parent / f"{p.name}-3d.html"
    recon_3d_figure(plan).write_html(html, include_plotlyjs=f"../{PLOTLY_JS}", full_html=True)
    return [png, html]


def _beyond(out_dir: Path) -> list[Path]:
    from uvnav.viz.figures_beyond import beyond_figures

    return beyond_figures(out_dir)


def chapter_renderers() -> ChapterRenderers:
    """The figure renderers of Chapters 3–7 and "beyond" for the experiments
    (:class:`uvnav.experiments.ExperimentContext`; imported lazily: a chapter's plotting extras
    load only when it draws)."""

    def ch3(db_path: Path, report_dir: Path, recorded: list[tuple[str, str, Any]]) -> list[Path]:
        from uvnav.viz.figures3d import render_ch3

        return render_ch3(db_path, report_dir, recorded)

    def ch4(out_dir: Path, scene_results: Any, summary: Any = None) -> list[Path]:
        from uvnav.viz.figures_ch4 import render_ch4

        return render_ch4(out_dir, scene_results, summary)

    def ch5(summary: Any, report_dir: Path) -> list[Path]:
        from uvnav.viz.figures_ch5 import render_ch5

        return render_ch5(summary, report_dir)

    def ch6(summary: Any, out_dir: Path) -> list[Path]:
        from uvnav.viz.figures_ch6 import render_ch6

        return render_ch6(summary, out_dir)

    return ChapterRenderers(ch3=ch3, ch4=ch4, ch5=ch5, ch6=ch6, ch7=render_ch7_plan, beyond=_beyond)


__all__ = ["ChapterSection", "chapter_renderers", "render_ch7_plan", "render_reproduction"]
