"""Figures and report of the thesis Chapter 2 reproduction (the renderer of
:func:`uvnav.bench.reproduce.reproduce`).

For each recorded thesis-scene episode a :func:`~uvnav.viz.figures.plot_episode` figure (Figs.
2.7–2.9 style), the Fig. 2.10 comparison of all controllers on the comparison scene, a summary
figure of the random campaign, then :func:`~uvnav.viz.report.write_report`.  The episode setups
(start, goal, vehicle limits) are rebuilt from the scenario with the stored seed; the trajectories
are read from the database.
"""

from __future__ import annotations

from pathlib import Path

from uvnav.bench.reproduce import RenderRequest, RenderResult
from uvnav.bench.store import ResultsStore
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

    out_dir = Path(req.report_dir)
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
    report = write_report(
        req.db_path,
        out_dir,
        figures=figures,
        table=req.table,
        title="uvnav — thesis Chapter 2 reproduction",
        summary_figure=False,
    )
    return RenderResult(report_path=report, figures=[p for p, _ in figures])
