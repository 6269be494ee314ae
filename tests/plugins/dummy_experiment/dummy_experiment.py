"""A third-party experiment in one file (the test plug-in of
``tests/plugins/test_plugins_experiment.py``): a small campaign of ``straight-v1`` on the
built-in ``open-field`` scene, stored in the results database, its row read back from the store,
one report section.

Its package would declare, and the test writes into a ``.dist-info`` folder::

    [uvnav.experiments]
    dummy = dummy_experiment:DUMMY
"""

from __future__ import annotations

from uvnav.bench.fingerprint import DB_NAME, code_fingerprint
from uvnav.bench.jobs import Job
from uvnav.bench.store import ResultsStore
from uvnav.experiments import Experiment, ExperimentContext, ExperimentRun
from uvnav.experiments.campaigns import run_checked
from uvnav.experiments.sections import ChapterSection

CAMPAIGN = "dummy-open-field"
LAW = "straight-v1"


def run(ctx: ExperimentContext) -> ExperimentRun:
    """``ctx.seeds`` episodes (2 by default) from ``ctx.start_seed``, then the success count."""
    seeds = range(ctx.start_seed, ctx.start_seed + (ctx.seeds or 2))
    jobs = [Job(controller=LAW, seed=s, scenario="open-field") for s in seeds]
    config = {"scene": "open-field", "controller": LAW, "fingerprint": code_fingerprint()}
    with ResultsStore(ctx.results_dir / DB_NAME) as store:
        counts = run_checked(store, [(CAMPAIGN, config, jobs)], workers=1, progress=False)
        df = store.episodes_frame(CAMPAIGN)
    df = df[df["seed"].isin(list(seeds))]
    ok = int((df["status"] == "success").sum())
    row = {
        "quantity": f"dummy: open-field success, {LAW}",
        "thesis": "not in the thesis",
        "measured": f"{ok} of {len(df)} (dummy-measured)",
        "note": f"seeds {seeds.start}-{seeds.stop - 1}",
    }
    section = ChapterSection(
        key="dummy",
        title="Dummy plug-in experiment",
        intro=f"{LAW} on open-field, {len(df)} seed(s), read back from the store.",
        rows=[row],
    )
    return ExperimentRun(sections=[section], rows=[row], campaigns=counts)


DUMMY = Experiment(
    name="dummy",
    title="A plug-in's experiment: straight-v1 on open-field (test)",
    run=run,
    seeded=True,
    order=85,  # between Chapter 7 (80) and beyond (90)
)
SHADOW = Experiment(name="ch2", title="A plug-in that takes a built-in's name", run=run)
