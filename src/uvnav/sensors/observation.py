"""What a controller is given: :class:`Observation` and per-obstacle :class:`ObstacleReading`.

These are the only inputs of ``Controller.act`` (DESIGN §2).  The thesis's Ch. 2 sensing model
(§2.2) is: for every obstacle within sensing range, the distance d_i (2.5) and nearest boundary
point r_min, the obstacle's shape and mass centre, and its velocity v_i and angular velocity u_i.
Whether v_i, u_i are the true values ("known") or finite-difference estimates is decided by the
simulator's sensing configuration and written in :attr:`ObstacleReading.velocity_source`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from itertools import chain
from operator import attrgetter
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray


@dataclass(frozen=True)
class ObstacleReading:
    """One obstacle as sensed from the robot's current position.

    Attributes:
        obstacle_id: stable index of the obstacle in the world (lets controllers track it).
        distance: distance d_i from the robot centre to the obstacle set [m] (0 when inside).
        nearest_point: r_min, the closest boundary point [m], shape (2,).
        centre: mass centre [m], shape (2,).
        velocity: v_i [m/s], shape (2,) (true or estimated, see ``velocity_source``).
        angular_velocity: u_i [rad/s].
        outline: boundary vertices in the world frame [m], (n, 2); empty for a disc.
        radius: disc radius [m]; 0 for a polygon.
        bounding_radius: radius of the centroid-centred disc containing the body [m].
        velocity_source: ``"known"`` (ground truth) or ``"estimated"``.
        position_std: the sensor's declared 1-sigma noise of ``centre`` [m] (per axis); 0 when
            the sensor declares none (exact sensing, or a source that does not know it).
    """

    obstacle_id: int
    distance: float
    nearest_point: FloatArray
    centre: FloatArray
    velocity: FloatArray
    angular_velocity: float
    outline: FloatArray
    radius: float
    bounding_radius: float
    velocity_source: str = "known"
    position_std: float = 0.0

    @classmethod
    def known(
        cls,
        obstacle_id: int,
        distance: float,
        nearest_point: FloatArray,
        centre: FloatArray,
        velocity: FloatArray,
        angular_velocity: float,
        outline: FloatArray,
        radius: float,
        bounding_radius: float,
    ) -> ObstacleReading:
        """A reading with its true velocity, built without the frozen ``__init__`` (which sets
        each field through ``object.__setattr__``): the same object, in half the time, for a
        simulator that builds thousands of readings a second."""
        r = object.__new__(cls)
        r.__dict__.update(
            obstacle_id=obstacle_id, distance=distance, nearest_point=nearest_point,
            centre=centre, velocity=velocity, angular_velocity=angular_velocity,
            outline=outline, radius=radius, bounding_radius=bounding_radius,
            velocity_source="known", position_std=0.0,
        )  # fmt: skip
        return r

    @property
    def is_disc(self) -> bool:
        return self.radius > 0.0

    @property
    def speed(self) -> float:
        """||v_i|| [m/s], computed once (kept in the instance's ``__dict__``, as
        ``functools.cached_property`` would keep it, without its per-access lock)."""
        got = self.__dict__.get("_speed")
        if got is None:
            got = self.__dict__["_speed"] = float(np.hypot(self.velocity[0], self.velocity[1]))
        return got


_SCALARS = attrgetter("distance", "angular_velocity", "radius", "bounding_radius")
_SOURCE = attrgetter("velocity_source")

#: readings as arrays: scalars (N, 4) (distance [m], angular velocity [rad/s], radius [m],
#: bounding radius [m]), centres (N, 2) [m], velocities (N, 2) [m/s], one row per reading
ReadingArrays = tuple[FloatArray, FloatArray, FloatArray]


def read_arrays(readings: tuple[ObstacleReading, ...]) -> ReadingArrays:
    """``readings`` as :data:`ReadingArrays`, read reading by reading (three passes).

    >>> z = np.zeros(2)
    >>> rd = ObstacleReading(3, 1.5, z, np.array([2.0, 0.0]), np.array([0.0, 1.0]), 0.0,
    ...                      np.zeros((0, 2)), 0.5, 0.5)
    >>> [a.tolist() for a in read_arrays((rd,))]
    [[[1.5, 0.0, 0.5, 0.5]], [[2.0, 0.0]], [[0.0, 1.0]]]
    """
    n = len(readings)
    scal = np.fromiter(chain.from_iterable(map(_SCALARS, readings)), float, count=4 * n)
    centre = np.array([rd.centre for rd in readings], dtype=float).reshape(n, 2)
    vel = np.array([rd.velocity for rd in readings], dtype=float).reshape(n, 2)
    return scal.reshape(n, 4), centre, vel


def any_estimated(readings: tuple[ObstacleReading, ...]) -> bool:
    """Some reading's velocity is ``"estimated"`` (asked of the sensor where it said, else of
    every reading)."""
    if isinstance(readings, Readings) and readings.all_known is not None:
        return not readings.all_known
    return "estimated" in map(_SOURCE, readings)


class Readings(tuple[ObstacleReading, ...]):
    """Readings, nearest first, that also give themselves as arrays (:attr:`arrays`), made on
    first use from the sensor's own arrays rather than from every reading.

    A sensor that reads its world from arrays returns this; a law that works on arrays reads
    :attr:`arrays` (one call) where it would read N reading objects.  Any other tuple of
    readings (filtered, estimated, noisy: every new tuple is a plain one, and so is a copy or
    an unpickled one) has no arrays and is read reading by reading (:func:`read_arrays`).

    >>> r = Readings.lazy((), lambda: (np.zeros((0, 4)), np.zeros((0, 2)), np.zeros((0, 2))))
    >>> r == (), r.arrays[0].shape
    (True, (0, 4))
    >>> type(r[:0]) is tuple  # a slice is a new, plain tuple
    True
    """

    _arrays: ReadingArrays | None = None
    _make: Callable[[], ReadingArrays] | None = None
    #: every reading's velocity is ``"known"`` (``None``: not said, read from the readings)
    all_known: bool | None = None

    @classmethod
    def lazy(
        cls,
        readings: Iterable[ObstacleReading],
        make: Callable[[], ReadingArrays],
        *,
        all_known: bool | None = None,
    ) -> Readings:
        """``readings`` whose :attr:`arrays` ``make()`` returns when first read (``make`` must
        read a state that no longer changes, and give what :func:`read_arrays` would);
        ``all_known``: the sensor says whether every velocity is the true one."""
        out = cls(readings)
        out._make, out.all_known = make, all_known
        return out

    @property
    def arrays(self) -> ReadingArrays:
        """The readings as :data:`ReadingArrays` (read-only; made once)."""
        got = self._arrays
        if got is None:
            got = self._make() if self._make is not None else read_arrays(self)
            for a in got:
                a.flags.writeable = False
            self._arrays, self._make = got, None
        return got

    def __reduce__(self) -> tuple[type[tuple[ObstacleReading, ...]], tuple[Any, ...]]:
        return tuple, (tuple(self),)


@dataclass(frozen=True)
class LidarScan:
    """Ranges [m] along ``angles`` [rad, world frame, in (-pi, pi]]; ``max_range`` where nothing
    is seen, NaN on dropout."""

    angles: FloatArray
    ranges: FloatArray
    max_range: float


@dataclass(frozen=True)
class Observation:
    """Everything a controller may use at one decision time.

    Attributes:
        time: simulation time [s].
        pose: the robot's own ``[x, y, theta]`` ([m], [m], [rad]).
        speed: the robot's current speed V_R [m/s] (its last applied command).
        goal: target point T [m], shape (2,).
        obstacles: readings of the obstacles within sensing range, nearest first.
        lidar: optional range scan.
        extras: readings of the plug-in sensors the scene mounts, by sensor name
            (:mod:`uvnav.sensors.plugins`).
    """

    time: float
    pose: FloatArray
    speed: float
    goal: FloatArray
    obstacles: tuple[ObstacleReading, ...] = ()
    lidar: LidarScan | None = None
    extras: Mapping[str, Any] = field(default_factory=dict)

    @property
    def position(self) -> FloatArray:
        return self.pose[:2]

    @property
    def heading(self) -> float:
        return float(self.pose[2])
