"""Third-party sensors of the 2D worlds (entry-point group ``uvnav.sensors``).

An entry point's name is the sensor's; it loads a callable
``sensor(pose, field, rng, **params) -> reading``: ``pose`` the robot's ``[x, y, theta]``
([m], [m], [rad]), ``field`` the bodies now (:class:`~uvnav.obstacles.ObstacleField`), ``rng`` the
world's sensing generator (the one its noise must come from, for determinism).  A scene lists the
sensors it mounts under ``sensing.plugins`` (``[{name: ..., params: {...}}]``); at every decision
the world calls each and hands its reading to the law in ``Observation.extras[name]``.  The
built-in sensors (exact readings, lidar) are not plug-ins and their names are refused.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from uvnav.core import load_plugins

SENSOR_GROUP = "uvnav.sensors"
#: names of the built-in sensors (a plug-in may not take them)
BUILTIN_SENSORS: tuple[str, ...] = ("exact", "lidar", "sonar-fan", "sonar-array")


def sensor_plugins() -> dict[str, Callable[..., Any]]:
    """The sensors of the :data:`SENSOR_GROUP` entry points by name (loaded once).

    Raises:
        RuntimeError: a plug-in takes a built-in name or another plug-in's.
    """
    return load_plugins(SENSOR_GROUP, BUILTIN_SENSORS, "sensor")


def sensor_plugin(name: str) -> Callable[..., Any]:
    """The plug-in sensor ``name``.

    Raises:
        KeyError: no such plug-in (the message lists the known ones).
    """
    plugins = sensor_plugins()
    if name not in plugins:
        known = ", ".join(sorted(plugins)) or "none installed"
        raise KeyError(f"unknown sensor plug-in {name!r} (known: {known})")
    return plugins[name]
