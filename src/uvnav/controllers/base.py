"""Controller contract and registry (DESIGN §2).

A controller is reset with the vehicle's limits, the goal and a generator, then asked for a command
at every decision time with nothing but its :class:`~uvnav.sensors.Observation`.  Controllers are
registered by versioned name (``zhang2019-v1``) with :func:`register`; third-party packages register
theirs through the ``uvnav.controllers`` entry-point group (the entry point must resolve to a
:class:`ControllerInfo` or to a controller class with a ``name`` attribute).

There is one registry for every vehicle.  Each entry says which vehicle it drives
(:func:`~uvnav.dynamics.vehicles.vehicle_names`: the command it returns and the observation it
reads) and what it senses;
:func:`available_controllers` lists one vehicle's laws (the unicycle's by default, the contract the
2D simulator and campaigns use) or all of them, and :func:`make_controller` builds unicycle laws
(:func:`make_law` builds any vehicle's).

Parameters are a frozen dataclass (``Params``) whose field docs carry units;
``make_controller`` builds
it from keyword arguments and rejects unknown names with a clear message.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from importlib import import_module
from importlib.metadata import entry_points
from typing import Any, ClassVar, Generic, Protocol, TypeVar, cast, runtime_checkable

import numpy as np
from pydantic import TypeAdapter, ValidationError

from uvnav.core import SENSINGS
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec
from uvnav.dynamics.vehicles import vehicle_names
from uvnav.sensors.observation import Observation
from uvnav.validation import describe_error


@runtime_checkable
class Controller(Protocol):
    """A navigation law for the unicycle (the 2D contract; 3D vehicles add their own commands)."""

    name: ClassVar[str]
    #: True when the law reads ground truth it could not sense (DESIGN §2 "oracle").
    oracle: bool

    def reset(self, spec: UnicycleSpec, goal: np.ndarray, rng: np.random.Generator) -> None: ...

    def act(self, obs: Observation) -> UnicycleCommand: ...

    @property
    def mode(self) -> str:
        """Name of the current mode (``"M1"``, ``"M2"``, ...) for the mode-switch metric."""
        ...


@dataclass(frozen=True)
class ControllerInfo:
    """Registry entry: versioned name, factory, parameter dataclass and a one-line summary."""

    name: str
    #: builds the law: a :class:`Controller` for the unicycle, a ``Controller3D`` or a
    #: ``Uuv2dController`` for the other vehicles
    factory: Callable[..., Any]
    params_type: type | None
    summary: str
    reference: str = ""
    #: obstacles must be slower than the robot for the law's guarantees (thesis (2.6)).
    requires_slower_obstacles: bool = False
    #: the observation the law reads: ``"exact"`` (range-limited exact readings, Ch. 2/3) or a
    #: sensor model's name (``"sonar-array"`` for the Ch. 5 nine-beam array)
    sensing: str = "exact"
    #: the vehicle the law drives (:func:`~uvnav.dynamics.vehicles.vehicle_names`: a built-in
    #: one or a plug-in's)
    vehicle: str = "unicycle"
    #: the parameter naming a law this one runs inside (``hybrid-v1``'s ``law``; its parameters
    #: in ``<name>_params``): that law's assumptions are this law's too
    inner_law: str = ""
    #: the law plans with its vehicle's acceleration limits (``UnicycleSpec.accel_max``,
    #: ``turn_accel_max``) when the vehicle has some; a law that does not is told so when it is
    #: run on such a vehicle (:func:`uvnav.scenarios.episodes.limits_note`)
    acceleration_limits: bool = False
    #: the law that replaces this one in the campaigns' default law lists
    #: (:func:`uvnav.experiments.crowds.crowd_laws`); the law stays registered, to reproduce
    #: older figures ("": not replaced)
    superseded_by: str = ""


_REGISTRY: dict[str, ControllerInfo] = {}
#: Modules of ``uvnav.controllers`` that register built-in unicycle laws when imported.
BUILTIN_MODULES: tuple[str, ...] = (
    "zhang2019",
    "zhang2019_v2",
    "savkin_wang2013",
    "straight",
    "orca",
    "orca_shared",
    "dwa",
    "apf",
    "hybrid",
)
#: Built-in modules of every vehicle kind (imported on demand by :func:`available_controllers`).
BUILTIN_MODULES_BY_VEHICLE: dict[str, tuple[str, ...]] = {
    "unicycle": BUILTIN_MODULES,
    "vehicle3d": ("zhang2020_3d", "apf3d", "vo3d", "zhang_uuv3d"),
    "uuv2d": ("zhang2022_uuv2d", "uuv2d_baselines"),
    "holonomic": ("holonomic", "zhang2019_v2", "crowd_ppo"),
}
_ENTRY_POINTS_LOADED = False


class UnknownControllerError(KeyError):
    """Raised for a name that is not registered."""


class ControllerParamsError(ValueError):
    """Raised for unknown or invalid controller parameters."""


def register(info: ControllerInfo) -> ControllerInfo:
    """Add ``info`` to the registry (registering the same entry again is a no-op).

    Raises:
        ValueError: ``info.vehicle`` is no vehicle's (:func:`vehicle_names`), ``info.sensing``
            not one of :data:`uvnav.core.SENSINGS`, or another law already has the name.
    """
    if info.vehicle not in vehicle_names():
        raise ValueError(
            f"controller {info.name!r}: unknown vehicle {info.vehicle!r}; "
            f"known: {', '.join(vehicle_names())}"
        )
    if info.sensing not in SENSINGS:
        raise ValueError(
            f"controller {info.name!r}: unknown sensing {info.sensing!r}; "
            f"known: {', '.join(SENSINGS)}"
        )
    old = _REGISTRY.get(info.name)
    if old is not None and old != info:
        raise ValueError(
            f"controller {info.name!r} is already registered (by {_origin(old)}); "
            "choose another name"
        )
    _REGISTRY[info.name] = info
    return info


def _origin(info: ControllerInfo) -> str:
    factory = info.factory
    return f"{getattr(factory, '__module__', '?')}.{getattr(factory, '__qualname__', '?')}"


def _load_entry_points() -> None:
    global _ENTRY_POINTS_LOADED
    if _ENTRY_POINTS_LOADED:
        return
    _ENTRY_POINTS_LOADED = True
    for ep in entry_points(group="uvnav.controllers"):
        obj = ep.load()
        if isinstance(obj, ControllerInfo):
            register(obj)
        else:
            register(
                ControllerInfo(
                    name=ep.name, factory=obj, params_type=getattr(obj, "Params", None), summary=""
                )
            )


def available_controllers(vehicle: str | None = "unicycle") -> dict[str, ControllerInfo]:
    """Registered controllers by name (built-ins and entry points).

    Args:
        vehicle: only the laws driving this vehicle (:func:`vehicle_names`); ``None`` = all.
    """
    kinds = vehicle_names() if vehicle is None else (vehicle,)
    _import_builtins(kinds)
    return {n: i for n, i in sorted(_REGISTRY.items()) if i.vehicle in kinds}


#: the vehicles whose built-in law modules are imported
_IMPORTED: set[str] = set()


def _import_builtins(kinds: Iterable[str]) -> None:
    """Import the built-in law modules of ``kinds`` (for their registration side effect), once,
    and the entry points."""
    for kind in kinds:
        if kind in _IMPORTED:
            continue
        if kind not in vehicle_names():
            raise ValueError(f"unknown vehicle {kind!r}; known: {', '.join(vehicle_names())}")
        for module in BUILTIN_MODULES_BY_VEHICLE.get(kind, ()):  # (a plug-in vehicle has none)
            import_module(f"uvnav.controllers.{module}")
        _IMPORTED.add(kind)
    _load_entry_points()


def controller_info(name: str, vehicle: str | None = None) -> ControllerInfo:
    """The registry entry of ``name`` (any vehicle, or only ``vehicle``'s laws).

    Raises:
        UnknownControllerError: not registered, or registered for another vehicle (the message
            names the vehicle it drives).
    """
    _import_builtins(vehicle_names())
    info = _REGISTRY.get(name)
    if info is None:
        known = available_controllers(vehicle)
        raise UnknownControllerError(f"unknown controller {name!r}; known: {', '.join(known)}")
    if vehicle is not None and info.vehicle != vehicle:
        raise UnknownControllerError(
            f"controller {name!r} drives the {info.vehicle} vehicle, not the {vehicle}"
        )
    return info


def build_params(params_type: type | None, params: dict[str, Any]) -> Any:
    """Instantiate the frozen parameter dataclass; one-line error for unknown/invalid fields."""
    if params_type is None:
        if params:
            raise ControllerParamsError(f"takes no parameters, got {', '.join(params)}")
        return None
    fields = {f.name for f in dataclasses.fields(params_type)}
    unknown = sorted(set(params) - fields)
    if unknown:
        raise ControllerParamsError(
            f"unknown parameter(s) {', '.join(unknown)}; known: {', '.join(sorted(fields))}"
        )
    hints = _field_types(params_type)
    params = {name: _as_tuple(hints[name], value) for name, value in params.items()}
    for name, value in params.items():
        try:  # each given value against its field's type, strictly ("yes" is not a bool)
            _type_adapter(hints[name]).validate_python(value, strict=True)
        except ValidationError as exc:
            raise ControllerParamsError(_first_problem(exc, name)) from None
        if isinstance(value, float) and math.isnan(value):  # never a meaningful setting
            raise ControllerParamsError(f"{name}: expected a number (got nan)")
    try:
        return params_type(**params)
    except (TypeError, ValueError) as exc:
        raise ControllerParamsError(str(exc)) from exc


def _as_tuple(hint: Any, value: Any) -> Any:
    """A list (how YAML, JSON and ``-p k=[a,b]`` write a sequence) given for a tuple field, as
    that tuple; any other value unchanged."""
    kinds = [hint, *typing.get_args(hint)] if typing.get_origin(hint) is types.UnionType else [hint]
    if isinstance(value, list) and any(typing.get_origin(k) is tuple for k in kinds):
        return tuple(value)
    return value


@functools.cache
def _field_types(params_type: type) -> dict[str, Any]:
    """The resolved type of each field of a parameter dataclass."""
    return typing.get_type_hints(params_type)


@functools.cache
def _type_adapter(hint: Any) -> TypeAdapter[Any]:
    return TypeAdapter(hint)


def _first_problem(exc: ValidationError, name: str) -> str:
    """One line for the first error of parameter ``name``'s check: ``NAME: problem``, worded
    as a scenario file's (:func:`uvnav.validation.describe_error`)."""
    err = exc.errors(include_url=False)[0]
    where = ".".join((name, *(str(part) for part in err["loc"])))
    return f"{where}: {describe_error(err, None)}"


def make_controller(name: str, *, oracle: bool = False, **params: Any) -> Controller:
    """Build a registered controller by name with keyword parameters.

    Args:
        name: versioned registry name, e.g. ``"zhang2019-v1"``.
        oracle: let the controller read true obstacle velocities (the simulator then gives it
            ground-truth rates even when sensing is configured as estimated).
        **params: fields of the controller's ``Params`` dataclass.
    """
    return cast(Controller, make_law(name, vehicle="unicycle", oracle=oracle, **params))


def requires_slower_obstacles(name: str, params: Mapping[str, Any] | None = None) -> bool:
    """Whether the law ``name`` with ``params`` assumes obstacles slower than the robot (thesis
    (2.6)): its own declaration, or that of the law it runs inside
    (:attr:`ControllerInfo.inner_law`: the parameter's value or its default)."""
    info = controller_info(name)
    if info.requires_slower_obstacles:
        return True
    if not info.inner_law:
        return False
    given = dict(params or {})
    inner = given.get(info.inner_law)
    if inner is None and info.params_type is not None:
        fields = {f.name: f for f in dataclasses.fields(info.params_type)}
        inner = fields[info.inner_law].default
    return requires_slower_obstacles(str(inner), given.get(f"{info.inner_law}_params"))


def make_law(name: str, *, vehicle: str | None = None, oracle: bool = False, **params: Any) -> Any:
    """Build any registered law by name (of ``vehicle`` only, when given) with keyword
    parameters; ``oracle`` lets it read ground truth (a law whose parameters make it an oracle,
    such as ``zhang2022-uuv3d-v1`` with ``locator=oracle``, stays one).

    Raises:
        UnknownControllerError: not registered (or another vehicle's law).
        ControllerParamsError: unknown or invalid parameters.
    """
    info = controller_info(name, vehicle)
    p = build_params(info.params_type, params)
    law = info.factory(p) if info.params_type is not None else info.factory()
    law.oracle = oracle or bool(getattr(law, "oracle", False))  # or an oracle by its params
    return law


def params_dict(params: Any) -> dict[str, Any]:
    """A parameter dataclass as a plain dict (for hashing and storage)."""
    return (
        dataclasses.asdict(params)
        if params is not None and dataclasses.is_dataclass(params) and not isinstance(params, type)
        else {}
    )


SpecT = TypeVar("SpecT")


class LawState(Generic[SpecT]):
    """State every law keeps whatever its vehicle: limits, goal, mode and the decision clock.

    Subclasses call ``super().__init__(default_spec, goal_dim)``, put their own per-episode state
    in :meth:`_reset_law`, and get the decision period from :meth:`decision_period`.
    """

    name: ClassVar[str]
    #: period [s] assumed at the first decision of an episode
    FIRST_PERIOD: ClassVar[float] = 0.1

    def __init__(self, spec: SpecT, goal_dim: int) -> None:
        self.oracle = False
        self._spec = spec
        self._goal = np.zeros(goal_dim)
        self._mode = "M1"
        self._last_t: float | None = None

    @property
    def mode(self) -> str:
        """Name of the current mode (for the mode-switch metric)."""
        return self._mode

    def reset(self, spec: SpecT, goal: np.ndarray, rng: np.random.Generator) -> None:
        self._spec = spec
        self._goal = np.asarray(goal, dtype=float)
        self._mode = "M1"
        self._last_t = None
        self._reset_law(rng)

    def _reset_law(self, rng: np.random.Generator) -> None:
        """Reset the law's own per-episode state (none by default)."""

    def decision_period(self, time: float) -> float:
        """Time [s] since the previous decision (``FIRST_PERIOD`` at the first, at least 1 ms, and
        ``FIRST_PERIOD`` for a non-finite time); advances the decision clock to ``time``."""
        if not math.isfinite(time):
            return self.FIRST_PERIOD
        period = self.FIRST_PERIOD if self._last_t is None else max(time - self._last_t, 1e-3)
        self._last_t = time
        return period


class UnicycleController(LawState[UnicycleSpec]):
    """:class:`LawState` of the unicycle laws (thesis Ch. 2 and the 2D baselines)."""

    def __init__(self) -> None:
        super().__init__(UnicycleSpec(1.0, 1.0), 2)


def is_number(value: object) -> bool:
    """True for a finite int or float (``bool`` excluded)."""
    return (
        isinstance(value, int | float) and not isinstance(value, bool) and np.isfinite(float(value))
    )


def check_params(
    params: Any, *, positive: Sequence[str] = (), non_negative: Sequence[str] = ()
) -> None:
    """Validate numeric fields of a parameter dataclass in ``__post_init__``.

    Raises:
        ValueError: naming the first field that is not a finite number > 0 (``positive``) or
            >= 0 (``non_negative``).
    """
    for name in positive:
        value = getattr(params, name)
        if not is_number(value) or value <= 0:
            raise ValueError(f"{name} must be a number > 0 (got {value!r})")
    for name in non_negative:
        value = getattr(params, name)
        if not is_number(value) or value < 0:
            raise ValueError(f"{name} must be a number >= 0 (got {value!r})")


def saturate(value: float, limit: float) -> float:
    """Clip ``value`` to [-limit, limit]; NaN maps to 0."""
    if not math.isfinite(value):
        return 0.0
    return float(min(max(value, -limit), limit))


def heading_rate_toward(angle_error: float, u_max: float, period: float) -> float:
    """Sliding-mode heading law with a boundary layer: ``u = U_max * sat(err / (U_max * period))``.

    Outside the layer this is the thesis's bang-bang ``U_max * sign(err)`` (eq. (2.15)); inside
    it the
    turn that cancels ``angle_error`` [rad] in one decision ``period`` [s], which removes the
    chattering a sampled sign function produces (docs/thesis-notes.md).
    """
    if period <= 0:
        return float(u_max * np.sign(angle_error))
    rate = angle_error / period  # (saturate(rate, u_max), inline)
    if not math.isfinite(rate):
        return 0.0
    return float(min(max(rate, -u_max), u_max))


def approach_speed(v_max: float, u_max: float, dist: float, beta: float) -> float:
    """The target-approach speed [m/s] of a unicycle ``dist`` [m] from T, T at angle ``beta``
    [rad] from its heading: V_max, lowered where T lies inside the minimum turning circle (radius
    V / U_max) to the largest speed whose turning circle passes through T,
    ``U_max dist / (2 sin|beta|)``, and to ``U_max dist / 2`` with T behind — so that the robot does
    not orbit T (``zhang2019-v1``'s note 10; ``savkin-wang2013-v1``'s M1).

    >>> approach_speed(1.0, 1.0, 10.0, 0.5)
    1.0
    >>> round(approach_speed(1.0, 1.0, 0.5, 1.2), 4)
    0.2682
    """
    v = v_max
    sin_b = abs(np.sin(beta))
    if sin_b > 1e-9:
        v = min(v, u_max * dist / (2.0 * sin_b))
    if abs(beta) > 0.5 * np.pi:  # target behind: the tightest circle through it
        v = min(v, u_max * dist / 2.0)
    return float(v)
