"""Documented limits on the size of what a file or an option can ask for.

A scenario, a campaign or a terrain request that would need more than these is refused when it
is read, with one line naming the field (or the option), the number it asks for and the limit,
instead of running for days or allocating petabytes.  They are module constants: a caller that
really needs more can raise them (``uvnav.scenarios.limits.MAX_EPISODE_STEPS = ...``) before
loading.

* :data:`MAX_EPISODE_STEPS` — integration steps of one episode, ``t_max / dt`` (10^7: about
  a day of simulated time at dt = 0.01 s; the built-ins need at most 10^4).
* :data:`MAX_CAMPAIGN_EPISODES` — episodes (jobs) of one campaign file (10^6).
* :data:`uvnav.validation.MAX_COORDINATE` — magnitude of a point's coordinates (10^6 m, the
  :data:`Coordinate` type of every scene kind's points) and of a pedestrian track's positions;
  :data:`MAX_MAGNITUDE` bounds every other number of a scene file (10^9).
* :data:`MAX_GRID_POINTS` — parameter sets of one controller entry's ``grid`` (10^4; each is
  checked by building the law when the file is read).

(The terrain of ``uvnav recon plan`` has its own: :data:`uvnav.recon.terrain.MAX_TERRAIN_NODES`.)
"""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, PrivateAttr, model_validator

from uvnav.scenarios.errors import FieldError
from uvnav.sim.ledger import decision_ratio, step_count
from uvnav.validation import coordinate_problem


def _coordinate(value: float) -> float:
    problem = coordinate_problem(value)
    if problem is not None:
        raise ValueError(f"{problem} (uvnav.validation.MAX_COORDINATE)")
    return value


#: A coordinate of a point [m]: finite and within :data:`uvnav.validation.MAX_COORDINATE`.
Coordinate = Annotated[float, AfterValidator(_coordinate)]


class FileModel(BaseModel):
    """Base of every scene file's models: unknown keys refused, no inf/nan, frozen."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)


class SceneModel(FileModel):
    """Base of a whole scene of any kind: ``source``, where it was read from (not a field)."""

    _source: str = PrivateAttr(default="<dict>")

    @property
    def source(self) -> str:
        """The file (or ``"<dict>"``) this scenario was read from, for error messages."""
        return self._source


class FieldEqualScene(SceneModel):
    """A scene equal to another when every field is equal: where it was read from does not
    count."""

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, type(self)):
            return NotImplemented
        return self.__dict__ == other.__dict__

    __hash__ = None  # type: ignore[assignment]  # lists inside: not hashable


class BoundedScene(SceneModel):
    """A scene whose numbers are refused above :data:`MAX_MAGNITUDE` (:func:`check_magnitudes`)."""

    @model_validator(mode="before")
    @classmethod
    def _bounded(cls, data: Any) -> Any:
        check_magnitudes(data)
        return data

    @model_validator(mode="after")
    def _bounded_values(self) -> BoundedScene:
        # YAML 1.1 reads ``1.0e300`` as a string, which pydantic turns into a number afterwards
        check_magnitudes(self)
        return self


#: most integration steps ``t_max / dt`` of one episode
MAX_EPISODE_STEPS = 10_000_000
#: most episodes of one campaign (scenario seeds x controller parameter sets)
MAX_CAMPAIGN_EPISODES = 1_000_000
#: most parameter sets of one campaign controller entry (the product of its grid's value counts)
MAX_GRID_POINTS = 10_000


def check_episode_steps(t_max: float, dt: float) -> None:
    """Refuse an episode of more than :data:`MAX_EPISODE_STEPS` integration steps.

    Raises:
        FieldError: on ``dt``, naming the number of steps and the limit.
    """
    steps = t_max / dt
    if not math.isfinite(steps) or steps > MAX_EPISODE_STEPS:
        raise FieldError(
            "dt",
            f"t_max / dt = {t_max:g} s / {dt:g} s = {steps:.3g} integration steps is more than "
            f"the limit of {MAX_EPISODE_STEPS:.0e} (uvnav.scenarios.limits.MAX_EPISODE_STEPS); "
            "raise dt or lower t_max",
        )


def check_timing(t_max: float, dt: float, control_period: float) -> None:
    """The timing of every scene kind: at most :data:`MAX_EPISODE_STEPS` integration steps, a
    ``t_max`` that is a whole multiple of ``dt`` and a decision period that is a positive whole
    multiple of ``dt`` (the worlds' rules: :mod:`uvnav.sim.ledger`).

    Raises:
        FieldError: on ``dt``, ``t_max`` or ``control_period``.
    """
    check_episode_steps(t_max, dt)
    rules = (("t_max", step_count, t_max), ("control_period", decision_ratio, control_period))
    for name, rule, value in rules:
        try:
            rule(value, dt)
        except ValueError as e:
            raise FieldError(name, str(e).removeprefix(f"{name} ")) from None


#: largest magnitude of a number in a scene file of any kind (sizes [m], speeds [m/s], times
#: [s]; points have the tighter :data:`Coordinate`): beyond it squared distances overflow
#: float64 in the geometry; seeds are exempt
MAX_MAGNITUDE = 1e9


def check_magnitudes(data: Any, path: str = "") -> None:
    """Refuse a number above :data:`MAX_MAGNITUDE` anywhere in a scene mapping or model (not
    seeds).

    Raises:
        FieldError: naming the field's dotted path and the number.
    """
    if isinstance(data, BaseModel):
        data = {name: getattr(data, name) for name in type(data).model_fields}
    if isinstance(data, dict):
        for key, value in data.items():
            if "seed" not in str(key):
                check_magnitudes(value, f"{path}.{key}" if path else str(key))
    elif isinstance(data, list | tuple):
        for i, value in enumerate(data):
            check_magnitudes(value, f"{path}.{i}" if path else str(i))
    elif (
        isinstance(data, int | float)
        and not isinstance(data, bool)
        and math.isfinite(data)
        and abs(data) > MAX_MAGNITUDE
    ):
        raise FieldError(
            path,
            f"{data:g} is above the limit of {MAX_MAGNITUDE:g} in magnitude "
            "(uvnav.scenarios.limits.MAX_MAGNITUDE)",
        )
