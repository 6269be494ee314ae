"""Experiments: every reproduction is one registered :class:`Experiment`.

An experiment has a ``name`` (what ``uvnav reproduce NAME`` takes), a one-line ``title``, whether
it runs random seeds (``seeded``: ``--seeds`` / ``--start-seed`` apply), its place in the report
(``order``), and ``run(ctx) -> ExperimentRun``: given an :class:`ExperimentContext` (folders, size,
workers, seeds, injected renderers) it runs its campaigns into the results store and returns its
report sections and its rows of the "thesis reported vs uvnav measured" table.  Its optional
``plan(ctx) -> [PlannedCampaign]`` lists the campaigns that run would run (name, config, jobs),
and ``stages`` names its stages (:func:`plan_experiment`, :func:`plan_summary`:
``uvnav reproduce NAME --plan``).

:func:`experiments` is the one registry: the built-ins (:mod:`uvnav.experiments.builtin`: the
thesis chapters ``ch2`` … ``ch7``, ``crowds``, ``regime``, ``beyond``) and the plug-ins of the
entry-point group :data:`EXPERIMENT_GROUP` (a built-in's name is refused)::

    [project.entry-points."uvnav.experiments"]
    mine = "my_package.mine:MINE"

:func:`run_experiment` is ``uvnav reproduce NAME``; :func:`run_all` is ``uvnav run`` (every
registered experiment in ``order``, one report over all their sections).
"""

from __future__ import annotations

from uvnav.experiments.planning import plan_experiment, plan_summary
from uvnav.experiments.protocol import (
    EXPERIMENT_GROUP,
    Experiment,
    ExperimentContext,
    ExperimentError,
    ExperimentRun,
    PlannedCampaign,
    ReportHook,
    Size,
)
from uvnav.experiments.registry import (
    builtin_experiments,
    check_options,
    experiments,
    get_experiment,
    plugin_experiments,
    section_order,
)
from uvnav.experiments.runner import (
    Reproduction,
    report_sections,
    run_all,
    run_experiment,
    saved_sections,
)

__all__ = [
    "EXPERIMENT_GROUP",
    "Experiment",
    "ExperimentContext",
    "ExperimentError",
    "ExperimentRun",
    "PlannedCampaign",
    "ReportHook",
    "Reproduction",
    "Size",
    "builtin_experiments",
    "check_options",
    "experiments",
    "get_experiment",
    "plan_experiment",
    "plan_summary",
    "plugin_experiments",
    "report_sections",
    "run_all",
    "run_experiment",
    "saved_sections",
    "section_order",
]
