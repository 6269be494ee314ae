"""Planar vehicles of the 2D world: the contract every one keeps, and the one registry of them
(the built-in unicycle and holonomic robot, and plug-ins of the entry-point group
:data:`VEHICLE_GROUP`).

The 2D world (:class:`uvnav.sim.episode.World2D`) owns the bodies, the sensor, the collision
judgement and the bookkeeping; a :class:`Vehicle2D` says what a command is (its limits,
saturation, the numbers a trajectory records, the box of an env's actions) and how its disc
moves under the command it holds.  A vehicle has a state of its own — its velocity now — which
an ideal vehicle takes from the held command at once and a vehicle with acceleration limits
approaches step by step; the sensor reports that velocity, and the bodies that see the robot
see it.  A vehicle is built from the scene's robot block (a
:class:`~uvnav.dynamics.unicycle.UnicycleSpec`: V_max, U_max, radius, kinematics; each vehicle
reads what applies to it), and a law that drives it names it as its ``vehicle``
(:class:`uvnav.controllers.ControllerInfo`): the law picks the vehicle in a 2D scene.

A plug-in vehicle is a class with the members of :class:`Vehicle2D`, exposed as an entry point
of :data:`VEHICLE_GROUP` under its name (a built-in vehicle's name is refused)::

    [project.entry-points."uvnav.vehicles"]
    point = "my_package.point:PointRobot"
"""

from __future__ import annotations

from typing import Any, ClassVar, Protocol, runtime_checkable

from uvnav.core import VEHICLES, load_plugins
from uvnav.dynamics.omni import OmniRobot
from uvnav.dynamics.unicycle import Unicycle, UnicycleSpec

#: entry-point group of plug-in planar vehicles
VEHICLE_GROUP = "uvnav.vehicles"


@runtime_checkable
class Vehicle2D(Protocol):
    """A disc-bodied planar vehicle (module docstring).

    Attributes:
        name: the vehicle's name (a law's ``vehicle``).
        command_names: what :meth:`pair` returns, with units (trajectory columns).
        spec: what a law is reset with: its limits and size (``v_max`` [m/s] and ``radius``
            [m] at least).
    """

    name: ClassVar[str]
    command_names: ClassVar[tuple[str, str]]
    spec: Any

    def rest(self) -> Any:
        """The command that stands still (held before the first decision)."""
        ...

    def reset(self) -> None:
        """At rest, holding :meth:`rest` (the start of an episode)."""
        ...

    def hold(self, cmd: Any) -> None:
        """Hold ``cmd`` (already saturated) from now on."""
        ...

    def saturate(self, cmd: Any, heading: float) -> tuple[Any, bool]:
        """``(the command the vehicle can apply, whether cmd was outside its limits)`` at
        ``heading`` [rad]; a non-finite command must not pass."""
        ...

    def pair(self, cmd: Any) -> tuple[float, float]:
        """The command as two numbers (an env's raw action; :attr:`command_names`)."""
        ...

    def command(self, a: float, b: float) -> Any:
        """The command of the two numbers :meth:`pair` gives."""
        ...

    def bounds(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """The box ``((low_a, low_b), (high_a, high_b))`` of :meth:`pair`'s numbers within the
        limits (an env's action box)."""
        ...

    def speed(self) -> float:
        """The speed now [m/s]."""
        ...

    def velocity(self, heading: float) -> tuple[float, float]:
        """The world-frame velocity now at ``heading`` [rad], [m/s]."""
        ...

    def speed_change(self, new: Any, old: Any) -> float:
        """The squared change of velocity command between two decisions [m^2/s^2] (the
        effort's speed term)."""
        ...

    def move(
        self, x: float, y: float, heading: float, dt: float, decision: bool, period: float
    ) -> tuple[float, float, float, float, float]:
        """One step ``dt`` [s] under the held command (``decision``: the step starts a decision
        period of ``period`` [s]): ``(x, y, heading, |heading change| [rad], effort's turn
        term)``."""
        ...

    def travel(self, dt: float) -> tuple[float, float]:
        """The path length [m] of the coming step ``dt`` [s] and the path's largest distance
        from the step's chord [m] (the collision sweep's slack)."""
        ...


def builtin_vehicles() -> dict[str, type]:
    """uvnav's own planar vehicles by name."""
    return {"unicycle": Unicycle, "holonomic": OmniRobot}


def plugin_vehicles() -> dict[str, type]:
    """The plug-in vehicles (:data:`VEHICLE_GROUP`) by name, loaded once.

    Raises:
        RuntimeError: a plug-in takes a built-in vehicle's name or another plug-in's.
    """
    return load_plugins(VEHICLE_GROUP, tuple(VEHICLES), "vehicle")


def vehicles_2d() -> dict[str, type]:
    """Every planar vehicle by name: the built-ins, then the plug-ins."""
    return {**builtin_vehicles(), **plugin_vehicles()}


def vehicle_names() -> tuple[str, ...]:
    """Every vehicle kind a law may drive: :data:`uvnav.core.VEHICLES`, then the plug-ins."""
    return (*VEHICLES, *plugin_vehicles())


def make_vehicle(name: str, robot: UnicycleSpec) -> Vehicle2D:
    """The planar vehicle ``name`` built from the scene's robot block ``robot``.

    Raises:
        ValueError: no planar vehicle has that name.
    """
    known = vehicles_2d()
    if name not in known:
        raise ValueError(f"no 2D vehicle {name!r}; known: {', '.join(known)}")
    vehicle: Vehicle2D = known[name](robot)
    return vehicle
