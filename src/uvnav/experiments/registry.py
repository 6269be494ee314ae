"""The one registry of experiments: the built-ins (:data:`uvnav.experiments.builtin.BUILTINS`)
and the plug-ins of the entry-point group :data:`~uvnav.experiments.protocol.EXPERIMENT_GROUP`,
in report order.  A plug-in is an :class:`~uvnav.experiments.protocol.Experiment` exposed under
its own name; a built-in's name (or ``all``, which is ``uvnav run``) is refused.
"""

from __future__ import annotations

import re

from uvnav.core import load_plugins
from uvnav.experiments.builtin import BUILTINS
from uvnav.experiments.protocol import EXPERIMENT_GROUP, Experiment, ExperimentError
from uvnav.validation import clip, one_line

#: Names no plug-in may take: the built-ins' and ``all``.
RESERVED: tuple[str, ...] = (*(e.name for e in BUILTINS), "all")
#: What an experiment's name (and a section's key: a file name) may be.
NAME_PATTERN = re.compile(r"[a-z0-9][a-z0-9_-]{0,63}")


def _ordered(found: dict[str, Experiment]) -> dict[str, Experiment]:
    return dict(sorted(found.items(), key=lambda kv: (kv[1].order, kv[0])))


def builtin_experiments() -> dict[str, Experiment]:
    """uvnav's own experiments by name, in report order."""
    return _ordered({e.name: e for e in BUILTINS})


def _checked(name: str, obj: object) -> Experiment:
    where = f"experiment plug-in {name!r} ({EXPERIMENT_GROUP})"
    if not isinstance(obj, Experiment):
        raise ExperimentError(f"{where} is a {type(obj).__name__}, not a uvnav Experiment")
    if obj.name != name:
        raise ExperimentError(f"{where} is named {obj.name!r}; the entry point must be its name")
    for key in (name, *obj.section_keys):
        if not NAME_PATTERN.fullmatch(key):
            raise ExperimentError(
                f"{where}: {key!r} is not a name of lower-case letters, digits, '-' and '_'"
            )
    return obj


def plugin_experiments() -> dict[str, Experiment]:
    """The plug-in experiments by name, loaded once.

    Raises:
        ExperimentError: a plug-in takes a reserved name or another plug-in's, cannot be loaded,
            or is not an :class:`~uvnav.experiments.protocol.Experiment` of its entry point's name.
    """
    try:
        found = load_plugins(EXPERIMENT_GROUP, RESERVED, "experiment")
    except RuntimeError as exc:  # a reserved name or two plug-ins of one name
        raise ExperimentError(clip(one_line(str(exc)), 300)) from None
    except Exception as exc:  # the plug-in's own import failed
        what = clip(one_line(f"{type(exc).__name__}: {exc}"), 240)
        raise ExperimentError(f"a plug-in of {EXPERIMENT_GROUP} failed: {what}") from None
    return {name: _checked(name, obj) for name, obj in found.items()}


def experiments() -> dict[str, Experiment]:
    """Every experiment by name, in report order (:attr:`Experiment.order`, then name).

    Raises:
        ExperimentError: a broken plug-in (:func:`plugin_experiments`).
    """
    return _ordered({**builtin_experiments(), **plugin_experiments()})


def get_experiment(name: str) -> Experiment:
    """The experiment ``name``.

    Raises:
        ExperimentError: no experiment has that name (the known ones listed), or a broken plug-in.
    """
    known = experiments()
    if name not in known:
        raise ExperimentError(
            f"unknown experiment {name!r}; known: {', '.join(known)}, or all (= uvnav run)"
        )
    return known[name]


def check_options(experiment: Experiment, seeds: int | None, start_seed: int) -> None:
    """Refuse ``seeds`` / ``start_seed`` an experiment does not take, or out of range.

    Raises:
        ExperimentError: one line naming the option.
    """
    if not experiment.seeded and (seeds is not None or start_seed != 0):
        seeded = [e.name for e in experiments().values() if e.seeded]
        raise ExperimentError(
            f"{experiment.name} runs no random seeds: --seeds/--start-seed apply to "
            f"{', '.join(seeded)}"
        )
    if seeds is not None and seeds < 1:
        raise ExperimentError(f"--seeds {seeds}: at least one seed")
    if start_seed < 0:
        raise ExperimentError(f"--start-seed {start_seed}: seeds are >= 0")


def section_order() -> tuple[str, ...]:
    """Every experiment's section keys, in report order."""
    return tuple(k for e in experiments().values() for k in e.section_keys)
