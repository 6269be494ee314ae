"""One report section per chapter: the contract between the reproductions and the HTML report.

Each chapter's run (:mod:`uvnav.experiments.builtin`, an experiment of :mod:`uvnav.experiments`
run by ``uvnav run`` and ``uvnav reproduce NAME``) turns what its reproduction returns (its summary
object: ``.table`` rows, ``.figures`` files) into a :class:`ChapterSection` with a
``*_section`` builder: the thesis chapters' builders are here, the
crowd section's and the regime map's beside their runs
(:func:`uvnav.experiments.crowds.crowds_section`, :func:`uvnav.experiments.regime.regime_section`).
The renderer (:func:`uvnav.viz.reproduction.render_reproduction`) hands the sections to
:func:`uvnav.viz.report.write_report`, which gives each a heading, its intro paragraph, its rows of
the "thesis reported vs uvnav measured" table, its figures with captions and links to its other
files (interactive 3D views, JSON results).  :func:`save_section` and :func:`load_sections` keep
the last section of every chapter next to the results database, in :data:`SECTION_ORDER`.

Figures are *drawn* only in ``viz``, the layer above this package: chapters whose figures need a
renderer receive it injected through :class:`ChapterRenderers` (the CLI builds one with
:func:`uvnav.viz.reproduction.chapter_renderers`), so ``uvnav.experiments`` never imports ``viz``
(DESIGN §1).

A new experiment builds its section itself and registers as an
:class:`uvnav.experiments.Experiment` (one module, see :mod:`uvnav.experiments`); the built-ins'
keys are listed in :data:`SECTION_ORDER` too, in the order of their registry.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

#: Image suffixes shown inline (``<img>``); other files become links.
IMAGE_SUFFIXES = frozenset({".png", ".gif", ".jpg", ".jpeg", ".svg", ".webp"})


class SectionFile(NamedTuple):
    """A file of a section and its caption (a figure if an image, else a link)."""

    path: Path
    caption: str


@dataclass
class ChapterSection:
    """One chapter's part of the report.

    Attributes:
        key: short id, used as the HTML anchor and the report sub-folder (``"ch3"``,
            ``"beyond"``).
        title: heading, e.g. ``"Chapter 3 — 3D flying robot among moving obstacles"``.
        intro: one paragraph: what was run (scenes, laws, seeds, quick/full mode).
        rows: this chapter's rows of the "thesis reported vs uvnav measured" table (dicts with
            ``quantity``, ``thesis``, ``measured``, ``note``).
        figures: images with captions, shown inline in this order.
        links: other files (interactive HTML views, JSON results) with a label, linked.
        notes: short remarks shown after the figures (what was not run, caveats).
    """

    key: str
    title: str
    intro: str
    rows: list[dict[str, str]] = field(default_factory=list)
    figures: list[SectionFile] = field(default_factory=list)
    links: list[SectionFile] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add_files(self, files: Iterable[SectionFile]) -> None:
        """Sort ``files`` into :attr:`figures` (images) and :attr:`links` (anything else)."""
        for f in files:
            (self.figures if f.path.suffix.lower() in IMAGE_SUFFIXES else self.links).append(f)

    def add_figures(
        self, paths: Iterable[Path], caption: Callable[[Path], str | None], what: str = ""
    ) -> None:
        """Add the existing ``paths`` with their captions (:func:`caption_files`); with ``what``,
        a note when the section has no figure ("the run had no ``what`` renderer")."""
        self.add_files(caption_files(paths, caption))
        if what and not self.figures:
            self.notes.append(f"No figures: the run had no {what} renderer.")


#: Draws Ch. 3 figures: ``(db_path, report_dir, [(scene, law, trajectory)]) -> files``.
Ch3Renderer = Callable[[Path, Path, list[tuple[str, str, Any]]], list[Path]]
#: Draws Ch. 4 figures: ``(out_dir, {(scene, law): result}, summary) -> files``.
Ch4Renderer = Callable[..., list[Path]]
#: Draws Ch. 5 / Ch. 6 figures: ``(summary, folder) -> files``.
SummaryRenderer = Callable[[Any, Path], list[Path]]
#: Draws one Ch. 7 plan: ``(plan, path prefix) -> files``.
PlanRenderer = Callable[[Any, Path], list[Path]]
#: Runs and draws the beyond-the-thesis figures into a folder: ``(out_dir) -> files``.
FolderRenderer = Callable[[Path], list[Path]]


@dataclass(frozen=True)
class ChapterRenderers:
    """The figure renderers of the chapters, injected by the caller (``None``: no figures)."""

    ch3: Ch3Renderer | None = None
    ch4: Ch4Renderer | None = None
    ch5: SummaryRenderer | None = None
    ch6: SummaryRenderer | None = None
    ch7: PlanRenderer | None = None
    beyond: FolderRenderer | None = None


#: The built-in sections' headings by key.
TITLES: dict[str, str] = {
    "ch2": "Chapter 2 — a unicycle among moving, deforming obstacles",
    "ch3": "Chapter 3 — a 3D flying robot with AR prediction",
    "ch4": "Chapter 4 — a UUV among shape-changing obstacles",
    "ch5": "Chapter 5 — a 3D UUV with nine sonars and a BPNN",
    "ch6": "Chapter 6 — a CNN that drives (PilotNet on CarRacing)",
    "ch7": "Chapter 7 — UAV reconnaissance of a terrain",
    "crowds": "Beyond the thesis — CrowdNav's crowds, every 2D law",
    "regime": "Beyond the thesis — where each law wins (regime map)",
    "beyond": "Beyond the thesis — global planners, hybrid navigation, multi-robot",
}


def mode_text(full: bool) -> str:
    """``"full mode"`` (``uvnav run --full``, thesis-size runs) or ``"quick mode"``."""
    return "full mode" if full else "quick mode"


def caption_files(
    paths: Iterable[Path], caption: Callable[[Path], str | None]
) -> list[SectionFile]:
    """``paths`` that exist, each with ``caption(path)`` (``None`` or empty: a caption made from
    the file name)."""
    out = []
    for p in paths:
        p = Path(p)
        if not p.is_file():
            continue
        out.append(SectionFile(p, caption(p) or p.stem.replace("-", " ").replace("_", " ")))
    return out


def rows_of(table: Sequence[Mapping[str, Any]]) -> list[dict[str, str]]:
    """Table rows as ``str -> str`` dicts (the report shows text)."""
    return [{str(k): "" if v is None else str(v) for k, v in r.items()} for r in table]


# ---------------------------------------------------------------------------------- Chapter 2


def ch2_section(
    rows: Sequence[Mapping[str, Any]],
    *,
    scenes: Sequence[str],
    controllers: Sequence[str],
    n_random: int,
    baselines: Sequence[str],
    start_seed: int = 0,
    n_baseline: int,
    n_crowd: int,
    crowd_generators: Sequence[str],
    crowd_v_max: float,
    full: bool,
) -> ChapterSection:
    """The Chapter 2 section; its figures are drawn by the report renderer from the database."""
    laws = ", ".join(controllers)
    intro = (
        f"Planar unicycle among moving obstacles ({mode_text(full)}). The thesis scenes "
        f"({', '.join(scenes) or 'none'}) ran once each (seed 0) with {laws}, trajectories "
        f"recorded; a random campaign on random-ch2 scenes ran seeds "
        f"{start_seed}–{start_seed + n_random - 1} with the "
        "same laws."
    )
    if baselines:
        intro += (
            f" Classical baselines ({', '.join(baselines)}) ran on the thesis scenes and "
            f"random-ch2 seeds {start_seed}–{start_seed + n_baseline - 1}; every law crossed "
            "pedestrian crowds "
            f"({', '.join(crowd_generators)}, {n_crowd} seeds each, robot V_max "
            f"{crowd_v_max:g} m/s)."
        )
    return ChapterSection(
        key="ch2",
        title=TITLES["ch2"],
        intro=intro,
        rows=rows_of(rows),
    )


# ---------------------------------------------------------------------------------- Chapter 3

_CH3_KINDS = {
    "trajectory": "the robot's path in 3D among the obstacles",
    "clearance": "distance to the nearest obstacle over time",
    "obstacle-motion": "the obstacles' motion",
    "prediction": "AR-predicted vs true obstacle motion",
}


def _ch3_caption(p: Path) -> str:
    parts = p.stem.split("--")
    if p.suffix == ".html":
        return f"{parts[0]} with {parts[-1]}: interactive 3D view (plotly)"
    if len(parts) == 3:
        scene, law, kind = parts
        return f"{scene} with {law}: {_CH3_KINDS.get(kind, kind)}."
    return ""


def ch3_section(
    summary: Any, *, full: bool, n_random: int | None = None, start_seed: int = 0
) -> ChapterSection:
    """The Chapter 3 section from a :class:`uvnav.experiments.ch3.Ch3Summary`."""
    import uvnav.experiments.ch3 as r3

    n = n_random if n_random is not None else (r3.FULL_SEEDS if full else r3.QUICK_SEEDS)
    intro = (
        f"3D flying robot among moving obstacles ({mode_text(full)}). The thesis-ch3 scenes ran "
        f"with {', '.join(r3.CONTROLLERS_3D)} (seed 0, obstacle rates estimated from sensing and "
        f"AR-predicted by the thesis's law); the random-ch3 campaign ran seeds "
        f"{start_seed}–{start_seed + n - 1} with "
        f"each law, obstacle motion known (oracle) and predicted; the AR one-step velocity "
        "prediction is compared with constant velocity."
    )
    study = getattr(summary, "study", None) or {}
    if study:
        intro += (
            f" What prediction buys: on random-ch3 and random-ch3-periodic (weaving / circling "
            f"bodies), AR vs constant-velocity k-step errors, and {r3.PREDICTION_LAW} with AR "
            f"prediction, constant velocity and the oracle on {int(study.get('seeds', 0))} seeds "
            "per family."
        )
    sec = ChapterSection(
        key="ch3",
        title=TITLES["ch3"],
        intro=intro,
        rows=rows_of(summary.table),
    )
    finding = getattr(summary, "finding", "")
    if finding:
        sec.notes.append(finding)
    sec.add_figures(getattr(summary, "figures", []) or [], _ch3_caption, "Chapter 3")
    return sec


# ---------------------------------------------------------------------------------- Chapter 4

_CH4_CAPTIONS = {
    "fig4-7-approach": "Fig. 4.7 reproduced: the UUV approaching a deforming obstacle, sonar "
    "cone and sensed boundary.",
    "fig4-8-decision": "Fig. 4.8 reproduced: the avoidance decision — tagged point, forecast "
    "circle and the tangent direction.",
    "fig4-4b-amaps": "Fig. 4.4(b) reproduced: the AMAPS map of sensed points at the decision.",
    "fig4-9-whole-run": "Fig. 4.9 reproduced: the whole run from I to E.",
}


def _ch4_caption(p: Path) -> str:
    base = _CH4_CAPTIONS.get(p.stem, "")
    if p.suffix == ".gif":
        return f"Animation of the Fig. 4.9 run ({p.name})."
    return base or f"{p.stem}: zhang2022-uuv2d-v1 run."


def ch4_section(
    summary: Any, *, full: bool, seeds: int | None = None, start_seed: int = 0
) -> ChapterSection:
    """The Chapter 4 section from a :class:`uvnav.experiments.ch4.Ch4Summary` (``seeds``:
    the run's override of every family's seed count)."""
    import uvnav.experiments.ch4 as r4

    n = seeds if seeds is not None else (r4.FULL_SEEDS if full else r4.QUICK_SEEDS)
    nn = seeds if seeds is not None else (r4.FULL_NOISE_SEEDS if full else r4.QUICK_NOISE_SEEDS)
    levels = ", ".join(f"noise {s:g} m" if s else f"dropout {d:.0%}" for s, d in r4.NOISE_LEVELS)
    intro = (
        f"Planar UUV with a viewing-cone sonar among shape-changing obstacles ({mode_text(full)}). "
        f"The thesis-ch4 scenes ran with {', '.join(r4.LAWS)} (seed 0, trajectories recorded); "
        f"the random-ch4 campaign ran {n} seeds per law (from seed {start_seed}), and a sensor "
        f"sweep ({levels}) {nn} seeds per level."
    )
    sec = ChapterSection(
        key="ch4",
        title=TITLES["ch4"],
        intro=intro,
        rows=rows_of(summary.table),
    )
    sec.add_figures(getattr(summary, "figures", []) or [], _ch4_caption, "Chapter 4")
    p = getattr(summary, "summary_path", None)
    if p is not None:
        sec.links += caption_files([Path(p)], lambda _p: "Chapter 4 results (JSON)")
    return sec


# ---------------------------------------------------------------------------------- Chapter 5


def _ch5_caption(p: Path) -> str:
    import uvnav.experiments.ch5_bpnn as b5

    s = p.stem
    if s == "ch5_array":
        return "Fig. 5.2: the nine-sonar array on the vehicle's front surface and its beams."
    if s == "ch5_learning_curve":
        return (
            "Learning curve: test error of the BPNN as the sample count grows, beside the "
            "min/argmin-of-readings baseline."
        )
    if (m := re.fullmatch(r"ch5_training_(n\w+)", s)) and (nv := b5.split_model_key(m[1])):
        kind = b5.VARIANT_LABELS[nv[1]]
        return f"BPNN training on {nv[0]} samples, {kind} network: loss per epoch."
    m = re.fullmatch(r"ch5_errors_(n[^_]+)_(test_group|independent)", s)
    if m and (nv := b5.split_model_key(m[1])):
        kind = b5.VARIANT_LABELS[nv[1]]
        where = "its own test group" if m[2] == "test_group" else "the independent test set"
        return (
            f"Figs. 5.5–5.8 style: errors and target-vs-output of the {nv[0]}-sample {kind} "
            f"network on {where}."
        )
    if m := re.fullmatch(r"ch5_anim_(.+)_([a-z]+)", s):
        return (
            f"Animation of {m[1]} with the {m[2]} locator: the vehicle (blue sphere), the "
            "deforming obstacles redrawn at each decision time, the located point to evade "
            "(black cross); right, a close-up around the vehicle."
        )
    if m := re.fullmatch(r"ch5_traj_(.+)_([a-z]+)_([0-9.]+)", s):
        return f"{m[1]}: the 3D run with the {m[2]} locator, sonar noise {m[3]} m."
    return ""


def ch5_section(summary: Any, *, full: bool) -> ChapterSection:
    """The Chapter 5 section from a :class:`uvnav.experiments.ch5.Ch5Summary`."""
    import json

    import uvnav.experiments.ch5 as r5
    import uvnav.experiments.ch5_bpnn as b5

    cfg: dict[str, Any] = {}
    p = getattr(summary, "json_path", None)
    if p is not None and Path(p).is_file():  # what was run, as ch5.json records it
        cfg = json.loads(Path(p).read_text(encoding="utf-8")).get("config", {})
    sizes = cfg.get("sizes", b5.FULL_SIZES if full else b5.QUICK_SIZES)
    seeds = cfg.get("seeds", b5.FULL_SEEDS if full else b5.QUICK_SEEDS)
    n_rand = cfg.get("n_random", r5.FULL_RANDOM if full else r5.QUICK_RANDOM)
    first = int(cfg.get("start_seed", 0))
    n_dense = cfg.get("n_dense", r5.FULL_DENSE if full else r5.QUICK_DENSE)
    noises = " and ".join(f"{x:g}" for x in cfg.get("noises", (0.0, 0.05) if full else (0.0,)))
    noises += " m"
    intro = (
        f"3D UUV with a nine-sonar array and a BPNN locator ({mode_text(full)}). The BPNN "
        f"(9→10→2: plain, residual, residual with a Huber loss) trained on "
        f"{', '.join(map(str, sizes))} samples with "
        f"{seeds} seeds each, tested on its own test group and on an independent set; "
        f"zhang2022-uuv3d-v1 then ran on the three thesis-ch5 scenes and random-ch5 seeds "
        f"{first}–{first + n_rand - 1} with the {', '.join(r5.LOCATORS)} locators, sonar "
        f"noise {noises}"
        + (
            f", and on random-ch5-dense seeds {first}–{first + n_dense - 1} (bodies closer "
            "than the law assumes, noise 0). "
            if n_dense
            else ". "
        )
        + f"Every closed-loop episode is a row of the results database (campaigns "
        f"{', '.join(r5.CAMPAIGNS)}); the summary with the failures is the JSON linked below."
    )
    sec = ChapterSection(
        key="ch5",
        title=TITLES["ch5"],
        intro=intro,
        rows=rows_of(summary.table),
    )
    sec.add_figures(getattr(summary, "figures", []) or [], _ch5_caption)
    if p is not None:
        sec.links += caption_files([Path(p)], lambda _p: "Chapter 5 results (JSON)")
    fails = list(getattr(summary, "failures", []) or [])
    if fails:
        shown = ", ".join(
            f"{f['scene']} ({f['locator']}, noise {f['noise_std']:g} m): {f['status']}"
            for f in fails[:8]
        )
        more = f" and {len(fails) - 8} more" if len(fails) > 8 else ""
        sec.notes.append(f"Closed-loop failures: {shown}{more}.")
    if not sec.figures:
        sec.notes.append("No figures: the run had no Chapter 5 renderer.")
    return sec


# ---------------------------------------------------------------------------------- Chapter 6

_CH6_CAPTIONS = {
    "fig6_1_cameras": "Fig. 6.1: the left, centre and right camera views.",
    "fig6_4_steering": "Fig. 6.4: steering angles of the collected frames before balancing.",
    "fig6_5_balanced": "Fig. 6.5: steering angles after balancing.",
    "fig6_6_split": "Fig. 6.6: the 8:2 training / validation split.",
    "fig6_7_augmentation": "Fig. 6.7: augmentation examples.",
    "fig6_8_loss": "Fig. 6.8: training and validation loss per epoch.",
}


def ch6_section(summary: Any | None, *, full: bool) -> ChapterSection:
    """The Chapter 6 section from a :class:`uvnav.experiments.ch6.Ch6Summary` (``None``: not
    run, as in a test-sized run)."""
    title = TITLES["ch6"]
    if summary is None:
        return ChapterSection(
            key="ch6",
            title=title,
            intro=f"Not run in this {mode_text(full)} run (a test-sized run leaves it out).",
            notes=[
                "Run it with uvnav reproduce ch6 [--full] (or uvnav run [--full]; the pipeline "
                "with every option: uvnav drive reproduce)."
            ],
        )
    size = getattr(summary, "size", {}) or {}
    how = ""
    if size:
        n = len(size["eval_seeds"])
        how = (
            f" Size: {size['episodes']} expert episodes of {size['collect_steps']} steps, "
            f"{size['epochs']} epochs, {n} held-out track{'s' if n != 1 else ''} of up to "
            f"{size['max_steps']} steps."
        )
    names = ", ".join(k for k in summary.closed_loop if k != "expert")
    sec = ChapterSection(
        key="ch6",
        title=title,
        intro=(
            f"PilotNet trained on frames of the pure-pursuit expert in CarRacing ({mode_text(full)}"
            "): collection, balancing, 8:2 split, training, then closed-loop laps on held-out "
            f"tracks ({names}; the expert for reference).{how}"
        ),
        rows=rows_of(summary.table),
    )
    if not full:
        sec.notes.append(
            "Quick size: a smoke run of the whole pipeline. A network trained this briefly does "
            "not drive well, so its closed-loop numbers are far below the thesis-size ones "
            "(uvnav reproduce ch6 --full or uvnav drive reproduce --full; measured figures in "
            "docs/thesis-notes.md)."
        )
    sec.add_figures(getattr(summary, "figures", []) or [], lambda p: _CH6_CAPTIONS.get(p.stem))
    return sec


# ---------------------------------------------------------------------------------- Chapter 7


def _ch7_caption(p: Path) -> str:
    name = p.stem.rsplit("-", 1)[0]
    if p.suffix == ".html":
        return f"{name}: interactive 3D view of terrain, waypoints and tours (plotly)"
    return (
        f"Fig. 7.4 style, {name}: terrain, the lattice waypoints at their lowest altitude and the "
        "UAV tours."
    )


def ch7_section(summary: Any, *, full: bool) -> ChapterSection:
    """The Chapter 7 section from a :class:`uvnav.experiments.ch7.Ch7Summary`."""
    import uvnav.experiments.ch7 as r7

    if full:
        plans = "synthetic and Jacksboro terrains × 300/600 m × R 20/30/50 m"
    else:
        plans = ", ".join(f"{k} {s:.0f} m with R = {r:.0f} m" for k, s, r in r7.QUICK_PLANS)
    sizes = "/".join(f"{s:.0f}" for s in r7.SIZES)
    radii = "/".join(f"{r:.0f}" for r in r7.RADII)
    intro = (
        f"UAV reconnaissance of a terrain ({mode_text(full)}). Stage 1 lattice counts for "
        f"{sizes} m squares and R = {radii} m; coverage on ground truth (a "
        f"{r7.CHECK_STEP:g} m grid, random points and footprint polygons, none of them a planning "
        f"sample) for {' and '.join(r7.COVERAGE_KINDS)} terrain, with the altitude it costs; "
        f"full plans (lattice, lowest altitudes, tours, Bézier paths) for {plans}."
    )
    sec = ChapterSection(
        key="ch7",
        title=TITLES["ch7"],
        intro=intro,
        rows=rows_of(summary.table),
    )
    sec.add_figures(getattr(summary, "figures", []) or [], _ch7_caption, "Chapter 7")
    return sec


# ----------------------------------------------------------------------------- beyond the thesis


def _beyond_caption(p: Path) -> str:
    s = p.stem
    if s == "beyond-paths":
        return (
            "Global planners on the office-floor grid (walls grown by the robot radius): A*, the "
            "visibility-graph path, and D* Lite's replan after a cabinet appears (red cells)."
        )
    if s == "beyond-office":
        return (
            "office-floor: the reactive law alone vs hybrid-v1 (D* Lite on the walls it senses) "
            "with the same law; the legend gives each run's outcome."
        )
    if s.startswith("beyond-swap-"):
        return (
            f"Antipodal swap of 16 robots, every robot running {s[len('beyond-swap-') :]}: paths, "
            "starts (circles), goals (stars), collisions (x)."
        )
    return ""


def beyond_section(
    rows: Sequence[Mapping[str, Any]], figures: Sequence[Path], *, full: bool
) -> ChapterSection:
    """The beyond-the-thesis section: global + local navigation (office floor) and multi-robot
    swap."""
    import uvnav.experiments.beyond as rb

    laws = rb.FULL_LAWS if full else rb.QUICK_LAWS
    swap = ", ".join(
        n
        + (" (tuned for peers)" if p == rb.ZHANG_MULTI else "")
        + (f" (responsibility {p['responsibility']})" if "responsibility" in p else "")
        for n, p in (rb.FULL_SWAP if full else rb.QUICK_SWAP)
    )
    intro = (
        f"What the thesis's conclusion names as the next step ({mode_text(full)}). Global + "
        f"local: on office-floor (seed 0), {', '.join(laws)} alone and inside hybrid-v1. "
        f"Multi-robot: the antipodal swap of 16 robots (seed 0), every robot running {swap}; "
        "ORCA (RVO2) is the multi-agent peer."
    )
    sec = ChapterSection(
        key="beyond",
        title=TITLES["beyond"],
        intro=intro,
        rows=rows_of(rows),
    )
    sec.add_figures(figures, _beyond_caption, "beyond-the-thesis")
    return sec


# ------------------------------------------------------------------------- sections on disk

#: Every section key in report order: the thesis chapters (the crowd section after Chapter 2's
#: ETH crowds), then what goes beyond the thesis.
SECTION_ORDER: tuple[str, ...] = (
    "ch2",
    "crowds",
    "regime",
    "ch3",
    "ch4",
    "ch5",
    "ch6",
    "ch7",
    "beyond",
)
#: Folder, next to the results database, of the last section each chapter's run produced.
SECTIONS_DIR = "sections"


def save_section(section: ChapterSection, folder: Path) -> Path:
    """Write ``section`` to ``folder/<key>.json`` (file paths absolute), replacing that chapter's
    previous section only; the report of a later single-chapter run (``uvnav reproduce CH``) or of
    ``uvnav report`` shows it beside the other chapters' sections."""
    import json

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    data = {
        "key": section.key,
        "title": section.title,
        "intro": section.intro,
        "rows": section.rows,
        "figures": [[str(Path(f.path).resolve()), f.caption] for f in section.figures],
        "links": [[str(Path(f.path).resolve()), f.caption] for f in section.links],
        "notes": section.notes,
    }
    path = folder / f"{section.key}.json"
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(json.dumps(data, indent=1, ensure_ascii=False), encoding="utf-8")
    tmp.replace(path)
    return path


def load_sections(folder: Path, keys: Sequence[str] = SECTION_ORDER) -> list[ChapterSection]:
    """The sections saved by :func:`save_section` in ``folder`` whose key is in ``keys``, in that
    order (default :data:`SECTION_ORDER`; :func:`uvnav.experiments.saved_sections` passes every
    registered experiment's); files that no longer exist are left out (noted in the section).  A
    missing folder: no sections."""
    import json

    out: list[ChapterSection] = []
    for key in keys:
        path = Path(folder) / f"{key}.json"
        if not path.is_file():
            continue
        try:
            d = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        sec = ChapterSection(
            key=str(d["key"]),
            title=str(d["title"]),
            intro=str(d["intro"]),
            rows=rows_of(d.get("rows", [])),
            notes=[str(n) for n in d.get("notes", [])],
        )
        missing = 0
        for kind in ("figures", "links"):
            for p, caption in d.get(kind, []):
                if Path(p).is_file():
                    getattr(sec, kind).append(SectionFile(Path(p), str(caption)))
                else:
                    missing += 1
        if missing:
            sec.notes.append(f"{missing} file(s) of this section no longer exist.")
        out.append(sec)
    return out
