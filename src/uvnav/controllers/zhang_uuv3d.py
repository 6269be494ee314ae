"""``zhang2022-uuv3d-v1``: the 3D underwater vehicle's sonar-array navigation law (thesis Ch. 5).

Reference: Y. Zhang and J. Zhang, "An Obstacle Avoidance Method for Sonar-based Robots Avoiding
Shape Changeable Obstacles in Underwater Environments", ICCAE 2022 (thesis Chapter 5, §5.3:
"The robot goes straight from the initial point A to the ending point B with the maximum speed
... It will take actions to avoid the obstacles ... when the obstacles appear in its surroundings";
the BPNN gives "the position information of the specific point needs to evade"; combined with the
"traditional biologically inspired algorithm" of Chapter 4, §4.3: the tag, the forecast circle
(4.11)-(4.12) and the tangent points (4.13)), on the vehicle (5.1)-(5.7).

Law, at each decision (the thesis states it for the plane; lifted here to 3D):

1. **Locate.**  A *locator* turns the sonar readings R(t) (5.8) into ``(d, k)``: the distance [m]
   from the hull to the nearest obstacle point and the number of the sensor whose beam holds it.
   Locators: :class:`GeometricLocator` (min/argmin of the readings, the baseline),
   :class:`ModelLocator` (any model with ``predict(inputs (n, 9)) -> (n, 2)`` — the trained BPNN of
   :mod:`uvnav.learning.bpnn` — fed the adapted readings), :class:`OracleLocator` (the true nearest
   point; an *oracle*: it reads ground truth the sonar cannot give).  The point to evade is
   ``p = s_k + d n_k`` (:func:`~uvnav.sensors.sonar_array.beam_point`).
2. **Switch.**  ``d > L`` (or no echo): target approach (M1, V_max straight to B, the turn
   bounded by U_max — :meth:`~uvnav.controllers.base3d.Vehicle3DController.approach`);
   ``d <= L``: avoidance (M2).
   A point behind the vehicle with respect to B (``(p - c) . (B - c) <= 0``) is no threat (the
   thesis returns to M1 "when the vehicle is away from the obstacle").  While in M2 the last point
   is remembered in world coordinates (the obstacles' centres are fixed), so that a point that
   slips out of the front-facing beams while the vehicle passes it is still evaded until it is
   behind or farther than L (the forecast history (4.11) keeps it too).
3. **Forecast sphere** (4.11)-(4.12) in 3D: centre p, radius ``R = mean ||p(t-k) - p(t-k+1)||``
   over the ``count`` decisions since M2 began, plus the hull radius and a ``margin`` [m] (the
   thesis treats the vehicle as a point; a body of radius rho needs rho more).
4. **Plane, tag and tangent point.**  In the plane through the vehicle c, B and p, the two tangent
   lines from c to the forecast circle; the tag picks the one on B's side of the line c -> p
   (the shorter way round) at the switch to M2, and is then kept as a rotation sense about that
   plane's normal for the whole avoidance (``fixed_tag``; the thesis decides the tag once too),
   so that two nearby points — the arms of Scene 2's narrow space — cannot make it chatter.
   The vehicle heads for that tangent point at V_max with the bounded turn rate.  Inside the
   forecast sphere it heads away from p, at ``escape_angle`` (default 120 deg) from the line
   c -> p on B's side (escape).

Ambiguities resolved (docs/thesis-notes.md): the thesis's '+'/'-' tag definition is given for the
line toward E in 2D; here it is "pass p on B's side", fixed per avoidance episode only when the
geometry does not decide it; the count reset (4.12) makes R = 0 at the first M2 decision.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Protocol, cast

import numpy as np

from uvnav.controllers.base import ControllerInfo, ControllerParamsError, register
from uvnav.controllers.base3d import Vehicle3DController
from uvnav.core import load_plugins
from uvnav.dynamics.vehicle3d import Vehicle3DCommand, Vehicle3DSpec
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.frames3d import horizontal_perpendicular
from uvnav.sensors.sonar_array import (
    N_SONARS,
    SonarArray,
    adapted_ranges,
    beam_point,
    nearest_beam,
)

NAME = "zhang2022-uuv3d-v1"
#: the built-in locators (:func:`make_locator`); others, such as ``network``, are plug-ins
BUILTIN_LOCATORS: tuple[str, ...] = ("geometric", "oracle")
#: entry-point group of locator plug-ins: a name -> ``factory(model: str) -> Locator``, where
#: ``model`` is the law's ``model`` parameter (uvnav's own ``network``: the trained BPNN)
LOCATOR_GROUP = "uvnav.locators"


def locator_plugins() -> dict[str, Any]:
    """The locator factories of the :data:`LOCATOR_GROUP` entry points by name (loaded once).

    Raises:
        RuntimeError: a plug-in takes a built-in name or another plug-in's.
    """
    return load_plugins(LOCATOR_GROUP, BUILTIN_LOCATORS, "locator")


def locator_names() -> tuple[str, ...]:
    """Every locator a ``locator`` parameter may name: the built-ins, then the plug-ins."""
    return (*BUILTIN_LOCATORS, *sorted(locator_plugins()))


@dataclass(frozen=True)
class SonarObservation3D:
    """What the Chapter 5 vehicle knows at a decision.

    Attributes:
        time: simulation time [s].
        position: c_r [m], (3,).
        heading: u_r (unit), (3,).
        speed: current V_r [m/s].
        goal: B [m], (3,).
        ranges: R(t) [m], (9,) — ``array.max_range`` without echo.
        echo: (9,) booleans, True where a sensor has an echo.
        array: the sonar array's geometry.
        truth_point: the true nearest obstacle point [m] — filled ONLY for oracle runs.
    """

    time: float
    position: FloatArray
    heading: FloatArray
    speed: float
    goal: FloatArray
    ranges: FloatArray
    echo: np.ndarray
    array: SonarArray
    truth_point: FloatArray | None = None


@dataclass(frozen=True)
class Located:
    """A located point to evade: hull-to-point distance [m], 1-based sensor, world point [m]."""

    distance: float
    index: int
    point: FloatArray


class Locator(Protocol):
    """Turns an observation into the point to evade (``None``: nothing in view)."""

    oracle: bool

    def locate(self, obs: SonarObservation3D) -> Located | None: ...


class GeometricLocator:
    """Baseline: the smallest reading and its sensor (min/argmin of R(t))."""

    oracle = False

    def locate(self, obs: SonarObservation3D) -> Located | None:
        if not np.any(obs.echo):
            return None
        r = np.where(obs.echo, obs.ranges, np.inf)
        k = int(np.argmin(r)) + 1
        d = float(r[k - 1])
        return Located(d, k, beam_point(obs.array, obs.position, obs.heading, k, d))


class Predictor(Protocol):
    def predict(self, inputs: FloatArray, offset: FloatArray | None = None) -> FloatArray: ...


class ModelLocator:
    """A learned locator: ``model.predict(adapted readings (1, 9), offset) -> (1, 2)`` gives the
    distance [m] and the (real-valued) sensor number, rounded and clipped to 1..9; ``offset`` is
    the min/argmin of the raw readings (used by residual networks, ignored by plain ones)."""

    oracle = False

    def __init__(self, model: Predictor) -> None:
        self.model = model

    def locate(self, obs: SonarObservation3D) -> Located | None:
        if not np.any(obs.echo):
            return None
        r = np.asarray(obs.ranges, dtype=float)
        x = adapted_ranges(obs.array, r)[None]
        offset = np.array([[float(r.min()), float(np.argmin(r)) + 1.0]])
        out = np.asarray(self.model.predict(x, offset), dtype=float).reshape(-1)
        d = max(float(out[0]), 0.0)
        k = int(min(max(round(float(out[1])), 1), N_SONARS))
        return Located(d, k, beam_point(obs.array, obs.position, obs.heading, k, d))


class OracleLocator:
    """ORACLE: the true nearest obstacle point (``obs.truth_point``), which no sonar gives."""

    oracle = True

    def locate(self, obs: SonarObservation3D) -> Located | None:
        if obs.truth_point is None:
            return None
        q = np.asarray(obs.truth_point, dtype=float)
        d = float(np.linalg.norm(q - obs.position)) - obs.array.hull_radius
        k = nearest_beam(obs.array, obs.position, obs.heading, q)
        return Located(d, k, q)


@dataclass(frozen=True)
class ZhangUUV3DParams:
    """Parameters of ``zhang2022-uuv3d-v1``.

    Attributes:
        switch_distance: L [m], avoidance when the located distance is <= L (> 0).
        margin: safety margin added to the forecast sphere [m] (>= 0).
        escape_angle: heading away from p, from the line c -> p, when inside the sphere [rad].
        max_history: decisions kept for the forecast radius (4.11) (>= 1).
        fixed_tag: keep the side chosen at the switch for the whole avoidance (True), or re-choose
            B's side at every decision (False; it can chatter between two close points).
        locator: what turns R(t) into the point to evade: geometric (min/argmin), network (the
            trained BPNN in ``model``), oracle (ORACLE: the true nearest point), or another
            plug-in of :data:`LOCATOR_GROUP`.
        model: the learned locator's model: for network, the BPNN checkpoint (path, or stem).
    """

    switch_distance: float = 3.0
    margin: float = 0.6
    escape_angle: float = math.radians(120.0)
    max_history: int = 20
    fixed_tag: bool = True
    locator: str = "geometric"
    model: str = ""

    def __post_init__(self) -> None:
        if not (math.isfinite(self.switch_distance) and self.switch_distance > 0):
            raise ValueError(f"switch_distance must be > 0 [m] (got {self.switch_distance!r})")
        if not (math.isfinite(self.margin) and self.margin >= 0):
            raise ValueError(f"margin must be >= 0 [m] (got {self.margin!r})")
        if not 0.5 * math.pi <= self.escape_angle <= math.pi:
            raise ValueError("escape_angle must be in [pi/2, pi] rad")
        if self.max_history < 1:
            raise ValueError("max_history must be >= 1")
        known = locator_names()
        if self.locator not in known:
            raise ValueError(f"locator must be one of {', '.join(known)} (got {self.locator!r})")
        if self.model and self.locator in BUILTIN_LOCATORS:
            raise ValueError(f"model is read by a learned locator only (locator={self.locator})")


def make_locator(name: str, model_path: Path | str = "", model: Predictor | None = None) -> Locator:
    """``geometric``, ``oracle``, a learned ``model`` (:class:`ModelLocator`), or the plug-in
    ``name`` given ``model_path`` (``network``: the BPNN checkpoint there).

    Raises:
        ValueError: unknown name, or a plug-in's refusal (``network`` without a readable
            checkpoint: :class:`~uvnav.learning.checkpoint.CheckpointError`, one line).
    """
    if name == "geometric":
        return GeometricLocator()
    if name == "oracle":
        return OracleLocator()
    if model is not None:
        return ModelLocator(model)
    plugins = locator_plugins()
    if name not in plugins:
        raise ValueError(f"unknown locator {name!r}; known: {', '.join(locator_names())}")
    return cast(Locator, plugins[name](str(model_path)))


def fixed_tag_direction(
    position: FloatArray,
    centre: FloatArray,
    radius: float,
    normal: FloatArray,
    escape_angle: float,
) -> FloatArray:
    """Tangent heading with the tag kept as a rotation sense about the unit ``normal`` fixed at
    the switch to avoidance: ``y = normal x (p - c)/|p - c|``, then as :func:`tangent_direction`."""
    x = np.asarray(centre, dtype=float) - position
    dist = float(np.linalg.norm(x))
    x = x / max(dist, 1e-12)
    y = np.cross(normal, x)
    ny = float(np.linalg.norm(y))
    y = horizontal_perpendicular(x) if ny < 1e-9 else y / ny
    if dist <= radius:
        return np.asarray(np.cos(escape_angle) * x + np.sin(escape_angle) * y)
    theta = math.asin(radius / dist)
    return np.asarray(math.cos(theta) * x + math.sin(theta) * y)


def tangent_direction(
    position: FloatArray,
    goal: FloatArray,
    centre: FloatArray,
    radius: float,
    fallback_normal: FloatArray,
    escape_angle: float,
) -> tuple[FloatArray, FloatArray, bool]:
    """The heading toward the tangent point on B's side of the forecast circle.

    Args:
        position: vehicle c [m]; goal: B [m]; centre: p [m]; radius: forecast radius [m].
        fallback_normal: plane normal used when c, B and p are collinear.
        escape_angle: angle from c -> p of the escape heading when c is inside the sphere [rad].

    Returns:
        ``(unit direction, plane normal, inside)``.
    """
    x = np.asarray(centre, dtype=float) - position
    dist = float(np.linalg.norm(x))
    x = x / max(dist, 1e-12)
    g = np.asarray(goal, dtype=float) - position
    y = g - float(g @ x) * x
    ny = float(np.linalg.norm(y))
    if ny < 1e-6 * max(1.0, float(np.linalg.norm(g))):
        nrm = np.asarray(fallback_normal, dtype=float)
        nrm = nrm - float(nrm @ x) * x
        if float(np.linalg.norm(nrm)) < 1e-9:
            nrm = horizontal_perpendicular(x)
        nrm = nrm / np.linalg.norm(nrm)
        y = np.cross(nrm, x)
    else:
        y = y / ny
        nrm = np.cross(x, y)
    if dist <= radius:
        return np.cos(escape_angle) * x + np.sin(escape_angle) * y, nrm, True
    theta = math.asin(radius / dist)
    return math.cos(theta) * x + math.sin(theta) * y, nrm, False


class ZhangUUV3D(Vehicle3DController):
    """The Chapter 5 law (module docstring) with the given ``locator``, or the one its
    parameters name (:func:`make_locator`; a ``network`` one reads its checkpoint here).

    Raises:
        ControllerParamsError: the parameters' checkpoint cannot be read (one line).
    """

    name: ClassVar[str] = NAME

    def __init__(self, params: ZhangUUV3DParams | None = None, locator: Locator | None = None):
        super().__init__()
        self.params = params or ZhangUUV3DParams()
        if locator is None:
            try:
                locator = make_locator(self.params.locator, self.params.model)
            except ValueError as exc:  # CheckpointError: a missing or unreadable file
                raise ControllerParamsError(f"model: {exc}") from None
        self.locator: Locator = locator
        self.oracle = bool(getattr(self.locator, "oracle", False))
        self._history: list[FloatArray] = []
        self._normal = np.array([0.0, 0.0, 1.0])
        self._memory: FloatArray | None = None
        self.last_located: Located | None = None

    def _reset_law(self, rng: np.random.Generator) -> None:
        self._history = []
        self._normal = np.array([0.0, 0.0, 1.0])
        self._memory = None
        self.last_located = None

    def reset(self, spec: Vehicle3DSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        super().reset(spec, goal, rng)

    def forecast_radius(self) -> float:
        """R(t) of (4.11): mean displacement of the located point over the kept decisions [m]."""
        h = self._history
        if len(h) < 2:
            return 0.0
        steps = np.linalg.norm(np.diff(np.stack(h), axis=0), axis=1)
        return float(steps.mean())

    def _threat(self, obs: Any, point: FloatArray) -> float | None:
        """Hull distance [m] to ``point`` if it is a threat: within L and not behind the vehicle
        with respect to B (``(p - c) . (B - c) > 0``); else ``None``."""
        rel = np.asarray(point, dtype=float) - obs.position
        d = float(np.linalg.norm(rel)) - self._spec.radius
        if d > self.params.switch_distance or float(rel @ (self._goal - obs.position)) <= 0.0:
            return None
        return d

    def act(self, obs: Any) -> Vehicle3DCommand:
        period = self.decision_period(float(obs.time))
        loc = self.locator.locate(obs)
        self.last_located = loc
        p = self.params
        point: FloatArray | None = None
        if (
            loc is not None
            and loc.distance <= p.switch_distance
            and self._threat(obs, loc.point) is not None
        ):
            point = np.asarray(loc.point, dtype=float)
            self._memory = point
        if (
            point is None
            and self._memory is not None
            and self._mode == "M2"
            and self._threat(obs, self._memory) is not None
        ):
            # the point left the beams: keep avoiding the remembered one (centres are fixed)
            point = self._memory
        if point is None:
            self._mode = "M1"
            self._history = []
            self._memory = None
            return self.approach(obs, period)
        if self._mode != "M2":
            # the tag: pass p on B's side, as a rotation sense about the normal of the plane
            # through c, B and p at the switch (kept for the whole avoidance)
            _, self._normal, _ = tangent_direction(
                obs.position, self._goal, point, 0.0, self._normal, p.escape_angle
            )
        self._mode = "M2"
        self._history.append(point)
        del self._history[: -p.max_history]
        radius = self.forecast_radius() + self._spec.radius + p.margin
        if p.fixed_tag:
            direction = fixed_tag_direction(
                obs.position, point, radius, self._normal, p.escape_angle
            )
        else:
            direction, _, _ = tangent_direction(
                obs.position, self._goal, point, radius, self._normal, p.escape_angle
            )
        return self.steer(obs, direction, self._spec.v_max, period)


register(
    ControllerInfo(
        name=NAME,
        factory=ZhangUUV3D,
        params_type=ZhangUUV3DParams,
        summary="Thesis Ch. 5: sonar array + located point (BPNN or min/argmin), forecast-sphere "
        "tangent avoidance in the plane through the vehicle, B and the point",
        reference="Y. Zhang, J. Zhang, ICCAE 2022; thesis Ch. 5 (and Ch. 4 §4.3)",
        sensing="sonar-array",
        vehicle="vehicle3d",
    )
)
