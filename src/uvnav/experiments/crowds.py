"""CrowdNav's crowds for every 2D law: the ``crowds`` section of ``uvnav run``.

:func:`reproduce_crowds` runs every registered 2D law — the unicycle laws and the holonomic ones
(:func:`uvnav.controllers.base.available_controllers`) — on CrowdNav's test cases of circle and
square crossing (``crowdnav-circle:<case>``, ``crowdnav-square:<case>``,
:mod:`uvnav.scenarios.crowdnav`: five ORCA pedestrians at 1 m/s who do not see the robot, robot
V_max 1 m/s, 24 s), cases ``start .. start + n - 1`` (:data:`QUICK_CASES` quick, :data:`FULL_CASES`
with ``full``: CrowdNav's whole test set), and builds one table: per scene and law the success and
collision rates with 95 % Wilson intervals, the timeouts, the mean time to goal of the successes,
and the social metrics (:mod:`uvnav.sim.social`: mean too-close frequency, mean intrusion time,
min separation, share of the collisions a pedestrian closed), beside the paper's ORCA figure
(:data:`PAPER_ORCA`: Chen, Liu, Kreiss, Alahi, ICRA 2019, Table I) on the row of
``orca-holonomic-v1`` on circle crossing, the paper's configuration.

Laws whose assumptions the scene breaks (``zhang2019-v1`` and ``savkin-wang2013-v1`` assume
obstacles slower than the robot, thesis (2.6); these pedestrians walk at the robot's V_max) are
stored and shown as ``refused`` in campaign :data:`CAMPAIGN`: that is the honest result of the
laws as specified.  Because the thesis's laws are the library's subject, they are *also* run
beyond that assumption, in a separate campaign :data:`BEYOND_CAMPAIGN` whose rows are labelled so
(the ETH crowd campaign of Ch. 2 does the same).  ``hybrid-v1`` follows its waypoints with
``zhang2019-v1`` inside and inherits that law's assumption (``ControllerInfo.inner_law``), so it is
refused and run beyond like it.

Both campaigns live in ``results_dir/uvnav.sqlite`` (:mod:`uvnav.experiments.campaigns`:
resumable, fingerprinted, additive).  The table shows the run's own cases (those it ran or found
stored); ``uvnav report`` rebuilds it from every stored case (:func:`crowd_rows`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from uvnav.bench.fingerprint import DB_NAME, code_fingerprint
from uvnav.bench.jobs import Job
from uvnav.bench.store import STATUS_ERROR, STATUS_REFUSED, ResultsStore
from uvnav.bench.summary import wilson_interval
from uvnav.experiments.campaigns import run_checked
from uvnav.experiments.rows import rate_text, table_row
from uvnav.experiments.sections import TITLES, ChapterSection, mode_text, rows_of

CAMPAIGN = "crowdnav"
BEYOND_CAMPAIGN = "crowdnav-beyond"
CAMPAIGNS: tuple[str, ...] = (CAMPAIGN, BEYOND_CAMPAIGN)
GENERATORS: tuple[str, ...] = ("crowdnav-circle", "crowdnav-square")
SCENE_NAMES = {"crowdnav-circle": "circle crossing", "crowdnav-square": "square crossing"}
#: the Chapter 2 campaign of real pedestrians (ETH ``eth`` and ``hotel``) tabulated beside them
ETH_CAMPAIGN = "crowds-eth"
ETH_NAMES = {"crowd-eth": "ETH eth walkway", "crowd-hotel": "ETH hotel walkway"}
#: Test cases per scene: quick (``uvnav run``) and full (``--full``: CrowdNav's test set).
QUICK_CASES, FULL_CASES = 100, 500
#: Chen, Liu, Kreiss, Alahi, ICRA 2019 (arXiv:1809.08835), Table I: ORCA, invisible robot,
#: 5 ORCA humans, circle crossing, 500 test cases.
PAPER_ORCA = {"success": 0.43, "collision": 0.57, "time_to_goal": 10.86}
PAPER_LAW, PAPER_SCENE = "orca-holonomic-v1", "crowdnav-circle"


def crowd_laws() -> tuple[list[str], list[str]]:
    """``(laws, beyond)``: every registered 2D law (unicycle, then holonomic) of the main campaign
    but those another law supersedes (``ControllerInfo.superseded_by``), and the laws also run
    beyond the scene's assumptions: those that require slower obstacles, themselves or through the
    law they run inside (``hybrid-v1``)."""
    from uvnav.controllers.base import available_controllers, requires_slower_obstacles

    infos = {**available_controllers("unicycle"), **available_controllers("holonomic")}
    laws = [n for n, info in infos.items() if not info.superseded_by]
    return laws, [n for n in laws if requires_slower_obstacles(n)]


@dataclass
class CrowdsSummary:
    """Outcome of :func:`reproduce_crowds`.

    Attributes:
        table: rows ``{"quantity", "thesis", "measured", "note"}``, measured from the store.
        db_path: the results database.
        laws: laws of the main campaign; beyond: laws of the beyond campaign.
        cases: test cases per scene; start_case: the first.
        campaigns: per campaign: ``jobs``, ``ran``, ``skipped``, ``errors``, ``wall_time`` [s].
        wall_time: total elapsed time [s].
    """

    table: list[dict[str, str]]
    db_path: Path
    laws: list[str]
    beyond: list[str]
    cases: int
    start_case: int
    full: bool
    campaigns: dict[str, dict[str, Any]] = field(default_factory=dict)
    wall_time: float = 0.0


def crowd_jobs(laws: Sequence[str], cases: range, *, beyond_assumptions: bool = False) -> list[Job]:
    """One job per scene, case and law (episode seed = case, as CrowdNav's test case)."""
    return [
        Job(
            controller=c,
            seed=g,
            generator=gen,
            generator_seed=g,
            beyond_assumptions=beyond_assumptions,
        )
        for gen in GENERATORS
        for g in cases
        for c in laws
    ]


def _laws(laws: Sequence[str] | None, beyond: Sequence[str] | None) -> tuple[list[str], list[str]]:
    """The main campaign's laws and those run beyond the scenes' assumptions."""
    default_laws, default_beyond = crowd_laws()
    main = list(default_laws if laws is None else laws)
    return main, list(default_beyond if beyond is None else beyond)


def campaign_plans(
    *,
    full: bool = False,
    cases: int | None = None,
    start_case: int = 0,
    laws: Sequence[str] | None = None,
    beyond: Sequence[str] | None = None,
) -> list[tuple[str, dict[str, Any], list[Job]]]:
    """The campaigns :func:`reproduce_crowds` runs with these arguments, (name, config, jobs)
    in order; nothing runs."""
    main, over = _laws(laws, beyond)
    n = cases if cases is not None else (FULL_CASES if full else QUICK_CASES)
    run_cases = range(start_case, start_case + n)
    fp = code_fingerprint()
    plans: list[tuple[str, dict[str, Any], list[Job]]] = [
        (
            CAMPAIGN,
            {"generators": list(GENERATORS), "controllers": main, "fingerprint": fp},
            crowd_jobs(main, run_cases),
        )
    ]
    if over:
        plans.append(
            (
                BEYOND_CAMPAIGN,
                {
                    "generators": list(GENERATORS),
                    "controllers": over,
                    "beyond_assumptions": True,
                    "fingerprint": fp,
                },
                crowd_jobs(over, run_cases, beyond_assumptions=True),
            )
        )
    return plans


def reproduce_crowds(
    results_dir: Path,
    *,
    full: bool = False,
    workers: int = 2,
    cases: int | None = None,
    start_case: int = 0,
    laws: Sequence[str] | None = None,
    beyond: Sequence[str] | None = None,
    progress: bool = False,
) -> CrowdsSummary:
    """Run the crowd campaigns into ``results_dir/uvnav.sqlite`` and build the table.

    Args:
        results_dir: folder of the results database (created).
        full: CrowdNav's 500 test cases per scene instead of :data:`QUICK_CASES`.
        workers: worker processes (1 = in-process).
        cases: test cases per scene (overrides the quick/full size).
        start_case: first test case.
        laws: laws of the main campaign (default :func:`crowd_laws`).
        beyond: laws run beyond the scene's assumptions (default :func:`crowd_laws`; empty: none).
        progress: rich progress bars on stderr.

    Raises:
        StaleCampaignError: a stored crowd campaign was made by other code.
    """
    tic = time.perf_counter()
    results_dir = Path(results_dir)
    results_dir.mkdir(parents=True, exist_ok=True)
    db_path = results_dir / DB_NAME
    main, over = _laws(laws, beyond)
    n = cases if cases is not None else (FULL_CASES if full else QUICK_CASES)
    run_cases = range(start_case, start_case + n)
    plans = campaign_plans(full=full, cases=cases, start_case=start_case, laws=laws, beyond=beyond)
    with ResultsStore(db_path) as store:
        done = run_checked(store, plans, workers=workers, progress=progress)
        table = crowd_rows(store, cases=run_cases, laws=main, beyond=over)
    return CrowdsSummary(
        table=table,
        db_path=db_path,
        laws=main,
        beyond=over,
        cases=n,
        start_case=start_case,
        full=full,
        campaigns=done,
        wall_time=time.perf_counter() - tic,
    )


# ------------------------------------------------------------------------------------ the table


def _mean(g: Any, name: str) -> float | None:
    col = g[name].dropna().astype(float)
    return float(col.mean()) if len(col) else None


def _social_note(ok: Any) -> str:
    parts = []
    freq = _mean(ok, "too_close_frequency")
    if freq is not None:
        parts.append(f"too close {freq:.1%} of decisions")
    intr = _mean(ok, "intrusion_time")
    if intr is not None:
        parts.append(f"intrusion {intr:.1f} s")
    sep = ok["min_separation"].dropna().astype(float)
    if len(sep):
        parts.append(f"min separation mean {sep.mean():.2f} m, worst {sep.min():.2f} m")
    by = ok.loc[ok["collision"].fillna(False).astype(bool), "collision_by"].dropna()
    if len(by):
        parts.append(f"collisions closed by a pedestrian {float((by == 'pedestrian').mean()):.0%}")
    return "; ".join(parts)


def _row(gen: str, law: str, g: Any, *, beyond: bool) -> dict[str, str]:
    base = gen.split("[", 1)[0]
    scene = ETH_NAMES[base] if base in ETH_NAMES else f"CrowdNav {SCENE_NAMES.get(gen, gen)}"
    quantity = f"{scene}, {law}" + (", beyond assumption (2.6)" if beyond else "")
    paper = law == PAPER_LAW and gen == PAPER_SCENE
    thesis = (
        f"paper's ORCA: success {PAPER_ORCA['success']:.2f}, collision "
        f"{PAPER_ORCA['collision']:.2f}, time {PAPER_ORCA['time_to_goal']:.2f} s "
        "(Chen et al. ICRA 2019, Table I, 500 cases)"
        if paper
        else "not reported (beyond the thesis)"
    )
    status = g["status"].astype(str)
    refused = int((status == STATUS_REFUSED).sum())
    errors = int((status == STATUS_ERROR).sum())
    ok = g[~status.isin((STATUS_REFUSED, STATUS_ERROR))]
    n = len(ok)
    if n == 0:
        if refused:
            why = str(g.loc[status == STATUS_REFUSED, "error"].dropna().iloc[0])
            measured = f"refused ({refused}/{len(g)} cases)"
            note = f"the law's assumption does not hold: {why}"
        else:
            measured, note = f"errors only ({errors})", ""
        return table_row(quantity, thesis, measured, note)
    st = ok["status"].astype(str)
    k_ok, k_hit = int((st == "success").sum()), int((st == "collision").sum())
    k_out = int((st == "timeout").sum())
    wins = ok[st == "success"]
    ttg = _mean(wins, "time_to_goal") if len(wins) else None
    measured = (
        f"success {rate_text(k_ok, n)}, collision {rate_text(k_hit, n)}, timeout {k_out / n:.2f} "
        f"(n={n}); time to goal {'n/a' if ttg is None else f'{ttg:.2f} s'}"
    )
    extra = []
    if paper:
        lo, hi = wilson_interval(k_ok, n)
        inside = lo <= PAPER_ORCA["success"] <= hi
        extra.append(
            f"paper's success {PAPER_ORCA['success']:.2f} {'inside' if inside else 'outside'} "
            "the 95 % interval"
        )
    if refused:
        extra.append(f"refused {refused}")
    if errors:
        extra.append(f"errors {errors}")
    note = "; ".join([*extra, _social_note(ok)] if _social_note(ok) else extra)
    row = table_row(quantity, thesis, measured, note)
    if paper:  # the paper's figure against ours: inside our 95 % interval or not
        row["verdict"] = "reproduced" if inside else "differs"
    return row


def crowd_rows(
    store: ResultsStore,
    *,
    cases: range | None = None,
    laws: Sequence[str] | None = None,
    beyond: Sequence[str] | None = None,
) -> list[dict[str, str]]:
    """The crowd table read from the store: per campaign (main, then beyond), scene and law one
    row (module docstring).  ``cases``: only those test cases (default every stored one);
    ``laws`` / ``beyond``: only those laws of each campaign, in that order (default all stored,
    sorted)."""
    rows: list[dict[str, str]] = []
    for name, chosen in ((CAMPAIGN, laws), (BEYOND_CAMPAIGN, beyond)):
        df = store.episodes_frame(name)
        if df.empty:
            continue
        if cases is not None:
            labels = {f"{gen}/{g:04d}" for gen in GENERATORS for g in cases}
            df = df[df["scenario"].astype(str).isin(labels)]
        family = df["family"].astype(str)
        ctrl = df["controller"].astype(str)
        order = list(chosen) if chosen is not None else sorted(set(ctrl))
        for gen in GENERATORS:
            for law in order:
                g = df[(family == gen) & (ctrl == law)]
                if len(g):
                    rows.append(_row(gen, law, g, beyond=name == BEYOND_CAMPAIGN))
    return rows + eth_rows(store)


def eth_rows(store: ResultsStore) -> list[dict[str, str]]:
    """Rows of the ETH crowd campaign of Chapter 2 (:data:`ETH_CAMPAIGN`, real pedestrians
    replayed; every law runs beyond (2.6) there on purpose), in the crowd table's form, when the
    store holds it: one row per walkway and law."""
    if store.campaign_id(ETH_CAMPAIGN) is None:
        return []
    df = store.episodes_frame(ETH_CAMPAIGN)
    rows: list[dict[str, str]] = []
    if df.empty:
        return rows
    family = df["family"].astype(str)
    ctrl = df["controller"].astype(str)
    for fam in sorted(set(family)):
        if fam.split("[", 1)[0] not in ETH_NAMES:
            continue
        for law in sorted(set(ctrl[family == fam])):
            g = df[(family == fam) & (ctrl == law)]
            row = _row(fam, law, g, beyond=False)
            row["thesis"] = "not reported (real pedestrians, who do not react to the robot)"
            rows.append(row)
    return rows


# ------------------------------------------------------------------------------ the section


def crowds_section(summary: CrowdsSummary) -> ChapterSection:
    """The crowd section of the report from a run's :class:`CrowdsSummary`."""
    first, last = summary.start_case, summary.start_case + summary.cases - 1
    size = (
        f"{summary.cases} test cases per scene (cases {first}–{last}"
        + (
            f"; the quick size, CrowdNav's test set is {FULL_CASES} cases: --full"
            if not summary.full and summary.cases < FULL_CASES
            else ""
        )
        + ")"
    )
    intro = (
        f"CrowdNav's crowds ({mode_text(summary.full)}): every 2D law on CrowdNav's circle and "
        f"square crossing (Chen, Liu, Kreiss, Alahi, ICRA 2019; five ORCA pedestrians at 1 m/s "
        f"who do not see the robot, robot V_max 1 m/s, 24 s), {size}: "
        f"{', '.join(summary.laws)}. Success and collision rates with 95 % Wilson intervals; "
        "the paper's ORCA figure stands beside orca-holonomic-v1 on circle crossing (CrowdNav's "
        "robot ORCA). The notes give the social metrics: mean share of decisions closer than "
        "0.2 m, mean time closer than 0.45 m, min separation, and the share of the collisions a "
        "pedestrian closed (these pedestrians do not avoid the robot). When the store holds the "
        "ETH crowd campaign of Chapter 2 (real pedestrians, replayed), its walkways follow in the "
        "same form. Laws that assume "
        "obstacles slower than the robot (thesis (2.6)) are refused here, and shown as refused: "
        "the pedestrians walk at the robot's speed, so their guarantees do not apply."
    )
    if summary.beyond:
        intro += (
            f" Because the thesis's laws are this library's subject, {', '.join(summary.beyond)} "
            "also ran beyond that assumption, as a separate row group ('beyond assumption "
            "(2.6)', campaign crowdnav-beyond), as in the ETH crowd campaign of Chapter 2 "
            "(hybrid-v1 drives with zhang2019-v1 inside and inherits its assumption)."
        )
    return ChapterSection(
        key="crowds",
        title=TITLES["crowds"],
        intro=intro,
        rows=rows_of(summary.table),
    )
