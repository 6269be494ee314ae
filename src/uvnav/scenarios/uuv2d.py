"""Scenario files for the Chapter-4 underwater scenes (planar UUV, shape-changing obstacles, sonar).

The 2D scenario schema (:mod:`uvnav.scenarios.schema`) describes a unicycle among rigid bodies;
these scenes need a different vehicle, a sonar and deforming bodies, so they get their own pydantic
v2 model here (the same conventions: ``extra="forbid"``, finite numbers, units in the field
descriptions, one-line :class:`~uvnav.scenarios.errors.ScenarioError` naming file, field and
problem) rather than a change to the 2D one.  A file says ``kind: uuv2d``.

Built-ins ship in ``uvnav/scenarios/builtin/ch4/`` (``thesis-ch4-*``; kept out of the 2D
library's folder so that its loader and tests see only 2D scenes), and the seeded generator
``random-ch4:<seed>`` (:func:`random_ch4_scenario`) is registered in :data:`UUV2D_GENERATORS`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, Field, ValidationError, model_validator

from uvnav.dynamics.holonomic import HolonomicSpec
from uvnav.obstacles.deforming import (
    MAX_RELATIVE_AMPLITUDE,
    DeformingStar,
    RigidShape,
    ShapeChanging,
    trap_inner_space,
    trap_polygon,
)
from uvnav.scenarios.errors import (
    FieldError,
    PlacementError,
    ScenarioError,
    from_validation_error,
)
from uvnav.scenarios.limits import BoundedScene, Coordinate, FileModel, check_timing
from uvnav.scenarios.loader import builtin_yaml_files, natural_key, parse_yaml
from uvnav.scenarios.params import typed_generator
from uvnav.sensors.sonar2d import SonarConfig
from uvnav.sim.episode_uuv2d import Uuv2dSetup, clearance_of, inside_any

Point2 = Annotated[tuple[Coordinate, Coordinate], Field(description="[x, y] [m]")]
BUILTIN_SUBDIR = "ch4"  # of the built-in scenario folder


_Model = FileModel


class VehicleSpec(_Model):
    """The planar UUV of (4.1)-(4.7)."""

    start: Point2 = Field(description="initial point I [m]")
    goal: Point2 = Field(description="end point E [m]")
    heading: float | None = Field(None, description="initial orientation [rad] (default: toward E)")
    v_max: float = Field(gt=0, description="V_max, bound of each velocity component [m/s]")
    u_max: float = Field(gt=0, description="U_max, bound of the turn rate [rad/s]")
    radius: float = Field(0.2, ge=0, description="radius of the vehicle's disc body [m]")


class SonarSpec(_Model):
    """The viewing-cone sonar (§4.2, Fig. 4.3)."""

    n_beams: int = Field(91, ge=2, description="number of beams")
    fov: float = Field(4.0 * math.pi / 3.0, gt=0, le=2 * math.pi, description="cone angle [rad]")
    max_range: float = Field(5.0, gt=0, description="range [m]")
    noise_std: float = Field(0.0, ge=0, description="range noise standard deviation [m]")
    dropout: float = Field(0.0, ge=0, lt=1, description="probability a beam returns nothing")

    def to_config(self) -> SonarConfig:
        return SonarConfig(
            n_beams=self.n_beams,
            fov=self.fov,
            max_range=self.max_range,
            noise_std=self.noise_std,
            dropout=self.dropout,
        )


class DeformingSpec(_Model):
    """A star-shaped body with a time-varying Fourier radius (fixed area and mass centre)."""

    type: Literal["deforming"]
    centre: Point2 = Field(description="mass centre at t = 0 [m]")
    area: float = Field(gt=0, description="fixed area [m^2]")
    max_rate: float = Field(ge=0, description="bound on the boundary's speed [m/s]")
    shape_seed: int = Field(0, ge=0, description="seed of the random Fourier coefficients")
    n_harmonics: int = Field(4, ge=1, le=8, description="number of harmonics (2..n+1)")
    roughness: float = Field(
        0.35, gt=0, le=MAX_RELATIVE_AMPLITUDE, description="total relative amplitude"
    )
    velocity: tuple[float, float] = Field(
        (0.0, 0.0), description="velocity of the mass centre [m/s]"
    )

    def to_shape(self) -> DeformingStar:
        """The body (memoised: the same spec gives the same, immutable, calibrated body)."""
        return _star(
            self.centre,
            self.area,
            self.max_rate,
            self.shape_seed,
            self.n_harmonics,
            self.roughness,
            self.velocity,
        )


@lru_cache(maxsize=4096)
def _star(
    centre: tuple[float, float],
    area: float,
    max_rate: float,
    seed: int,
    n_harmonics: int,
    roughness: float,
    velocity: tuple[float, float],
) -> DeformingStar:
    return DeformingStar.random(
        np.random.default_rng(seed),
        centre,
        area,
        max_rate=max_rate,
        n_harmonics=n_harmonics,
        roughness=roughness,
        velocity=velocity,
    )


class TrapSpec(_Model):
    """The Fig. 4.2(b) shape: a thick C with a deep inner space behind a narrow mouth."""

    type: Literal["trap"]
    centre: Point2 = Field(description="centre of the inner space [m]")
    outer: float = Field(1.5, gt=0, description="outer radius [m]")
    inner: float = Field(1.0, gt=0, description="radius of the inner space [m]")
    mouth: float = Field(0.25, gt=0, description="width of the entry [m]")
    facing: float = Field(0.0, description="direction the mouth opens to [rad]")

    @model_validator(mode="after")
    def _sizes(self) -> TrapSpec:
        if not (self.mouth < 2 * self.inner and self.inner < self.outer):
            raise FieldError("mouth", "need mouth < 2 inner and inner < outer")
        return self

    def to_shape(self) -> RigidShape:
        return RigidShape.from_vertices(
            trap_polygon(
                self.centre,
                outer=self.outer,
                inner=self.inner,
                mouth=self.mouth,
                facing=self.facing,
            )
        )

    def inner_space(self) -> np.ndarray:
        return trap_inner_space(self.centre, inner=self.inner)


ShapeSpec = Annotated[DeformingSpec | TrapSpec, Field(discriminator="type")]


class ControllerChoice(_Model):
    """The law a scene runs with by default (a law registered with ``vehicle="uuv2d"``)."""

    name: str = Field("zhang2022-uuv2d-v1", min_length=1)
    params: dict[str, Any] = Field(default_factory=dict)


class Uuv2dScenario(BoundedScene):
    """A Chapter-4 scene: vehicle, sonar, shape-changing obstacles, timing, default law."""

    kind: Literal["uuv2d"] = Field(description="marks a Chapter-4 UUV scene")
    name: str = Field(min_length=1)
    description: str = Field("", description="what the scene is and where it comes from")
    dt: float = Field(0.05, gt=0, description="integration step [s]")
    control_period: float = Field(0.2, gt=0, description="decision period [s], multiple of dt")
    t_max: float = Field(60.0, gt=0, description="time limit [s]")
    goal_tolerance: float = Field(0.2, gt=0, description="E is reached within this distance [m]")
    switch_distance: float = Field(1.5, gt=0, description="the chapter's L [m] (law default)")
    vehicle: VehicleSpec
    sonar: SonarSpec = Field(default_factory=lambda: SonarSpec.model_validate({}))
    obstacles: list[ShapeSpec] = Field(default_factory=list)
    controller: ControllerChoice = Field(
        default_factory=lambda: ControllerChoice.model_validate({})
    )

    @model_validator(mode="after")
    def _consistent(self) -> Uuv2dScenario:
        check_timing(self.t_max, self.dt, self.control_period)
        shapes = [o.to_shape() for o in self.obstacles]
        outlines = [s.outline(0.0) for s in shapes]
        gap, j = clearance_of(self.vehicle.start, outlines, self.vehicle.radius)
        if gap < 0:
            raise FieldError("vehicle.start", f"vehicle disc overlaps obstacle {j} at t=0")
        if inside_any(self.vehicle.goal, outlines):
            raise FieldError("vehicle.goal", "lies inside an obstacle at t=0")
        return self

    def shapes(self) -> list[ShapeChanging]:
        return [o.to_shape() for o in self.obstacles]

    def forbidden(self) -> list[np.ndarray]:
        """Inner spaces of the trap shapes (regions the vehicle must never enter)."""
        return [o.inner_space() for o in self.obstacles if isinstance(o, TrapSpec)]

    def to_setup(self) -> Uuv2dSetup:
        """The episode this scene describes (the seed of an episode only drives sonar noise and
        the law's generator; the shapes are fixed by their ``shape_seed``)."""
        v = self.vehicle
        start, goal = np.asarray(v.start, dtype=float), np.asarray(v.goal, dtype=float)
        heading = v.heading
        if heading is None:
            heading = math.atan2(goal[1] - start[1], goal[0] - start[0])
        return Uuv2dSetup(
            spec=HolonomicSpec(v_max=v.v_max, u_max=v.u_max, radius=v.radius),
            start=np.array([start[0], start[1], heading]),
            goal=goal,
            shapes=self.shapes(),
            dt=self.dt,
            control_period=self.control_period,
            t_max=self.t_max,
            goal_tolerance=self.goal_tolerance,
            sonar=self.sonar.to_config(),
            forbidden=self.forbidden(),
        )


def uuv2d_from_dict(data: dict[str, Any], source: str = "<dict>") -> Uuv2dScenario:
    """Validate a mapping as a :class:`Uuv2dScenario`.

    Raises:
        ScenarioError: one line naming ``source``, the field and the problem.
    """
    if not isinstance(data, dict):
        raise ScenarioError(source, "<root>", "expected a mapping of scenario fields")
    try:
        sc = Uuv2dScenario.model_validate(data)
    except ValidationError as exc:
        err = from_validation_error(exc, source)
        # hide pydantic's discriminator segment: obstacles.0.trap.mouth -> obstacles.0.mouth
        path = re.sub(r"^(obstacles\.\d+)\.(deforming|trap)(?=\.|$)", r"\1", err.path)
        raise ScenarioError(source, path, err.problem) from None
    sc._source = source
    return sc


# ------------------------------------------------------------------------------------ library
def _builtin_files() -> dict[str, Any]:
    return builtin_yaml_files(BUILTIN_SUBDIR)


def list_uuv2d_builtin() -> list[str]:
    """Names of the Chapter-4 built-in scenes, in natural order."""
    return sorted(_builtin_files(), key=natural_key)


def uuv2d_builtin_text(name: str) -> str:
    files = _builtin_files()
    if name not in files:
        raise ScenarioError(name, "", f"unknown Chapter-4 scene (known: {', '.join(files)})")
    return str(files[name].read_text(encoding="utf-8"))


def load_uuv2d_scenario(name_or_path: str | Path) -> Uuv2dScenario:
    """A Chapter-4 scene by built-in name, ``random-ch4:<seed>``, or YAML path.

    Raises:
        ScenarioError: missing, malformed or invalid.
    """
    text_name = str(name_or_path)
    if ":" in text_name and not Path(text_name).exists():
        gen, _, seed = text_name.partition(":")
        if gen in UUV2D_GENERATORS:
            if not seed.isdigit():
                raise ScenarioError(text_name, "", f"expected {gen}:<non-negative integer seed>")
            return UUV2D_GENERATORS[gen](int(seed))
    if text_name in _builtin_files():
        return uuv2d_from_dict(
            parse_yaml(uuv2d_builtin_text(text_name), f"{text_name}.yaml"), f"{text_name}.yaml"
        )
    path = Path(text_name)
    if not path.is_file():
        raise ScenarioError(
            text_name,
            "",
            f"no such file or Chapter-4 scene (built-ins: {', '.join(list_uuv2d_builtin())}; "
            f"generators: {', '.join(UUV2D_GENERATORS)}:<seed>)",
        )
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(text_name, "", f"cannot read: {exc}") from None
    return uuv2d_from_dict(parse_yaml(text, text_name), text_name)


# ---------------------------------------------------------------------------------- generator
CH4_START = (0.0, 0.0)
CH4_GOAL = (10.0, 10.0)
CH4_V_MAX = 1.0  # [m/s], per component
CH4_U_MAX = 2.0  # [rad/s]
CH4_RADIUS = 0.2  # [m]


#: placement attempts per body asked for (random-ch4): the family always made 200; a scene
#: complete within them is drawn as it always was, the further ones run only for a scene that
#: would otherwise be short (none of seeds 0-199 is)
_MORE_TRIES = 400
#: random-ch4-hard: a placement (40 draws per body) that leaves the scene short is followed by
#: up to this many fresh ones from the same generator (24 of seeds 0-199 were short after the
#: first); a scene complete after the first is drawn as it always was
_RETRY_ROUNDS = 10

_Rate = Annotated[float, Field(gt=0, lt=CH4_V_MAX)]


def _rate_range(value: tuple[float, float]) -> tuple[float, float]:
    if value[0] > value[1]:
        raise ValueError(f"need min <= max (got {list(value)})")
    return value


RateRange = Annotated[tuple[_Rate, _Rate], AfterValidator(_rate_range)]


@typed_generator("random-ch4")
def random_ch4_scenario(
    seed: int,
    *,
    n_obstacles: Annotated[
        int | None, Field(ge=1, le=10, description="number of bodies (drawn in 1..5 when null)")
    ] = None,
    noise_std: Annotated[float, Field(ge=0, description="sonar range noise [m]")] = 0.0,
    dropout: Annotated[float, Field(ge=0, le=1, description="sonar dropout probability")] = 0.0,
    max_rate: Annotated[
        RateRange,
        Field(description="range of the bodies' deformation rate bound [m/s] (below V_max)"),
    ] = (0.05, 0.3),
) -> Uuv2dScenario:
    """A random Chapter-4 scene within the chapter's assumptions (seeded).

    I = [0, 0], E = [10, 10] as in Figs. 4.7-4.9; 1-5 deforming stars (area 0.5-4 m^2, boundary
    rate drawn from ``max_rate`` [m/s], slower than the vehicle) placed near the I-E line by
    rejection so that (a) every body's bounding disc stays 1.5 m from I and E, and (b) two bodies'
    bounding discs are at least 2 (vehicle radius + 0.3 m) apart: the chapter does not consider
    colliding obstacles, and a gap the vehicle cannot pass would turn a pair into one non-star
    body with a narrow inner space (Fig. 4.2(b), excluded).  At least one body lies across the
    I-E line.

    ``n_obstacles`` may ask for up to 10 bodies and ``max_rate`` for deformation rates up to
    (below) V_max, the chapter's assumption.

    Args:
        seed: scene number.

    Raises:
        ScenarioError: a parameter out of range (one line).
        PlacementError: the bodies drawn cannot all be placed.
    """
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 6)) if n_obstacles is None else int(n_obstacles)
    start = np.array(CH4_START)
    goal = np.array(CH4_GOAL)
    u = (goal - start) / np.hypot(*(goal - start))
    normal = np.array([-u[1], u[0]])
    gap = 2.0 * (CH4_RADIUS + 0.3)
    placed: list[tuple[np.ndarray, float]] = []
    specs: list[dict[str, Any]] = []
    for _ in range(_MORE_TRIES * n):
        if len(specs) == n:
            break
        area = float(rng.uniform(0.5, 4.0))
        shape_seed = int(rng.integers(0, 2**31 - 1))
        rate = float(rng.uniform(*max_rate))
        along = float(rng.uniform(2.5, 11.6))
        lateral = float(rng.uniform(-0.3, 0.3)) if not specs else float(rng.uniform(-2.5, 2.5))
        centre = start + along * u + lateral * normal
        spec = {
            "type": "deforming",
            "centre": [round(float(centre[0]), 3), round(float(centre[1]), 3)],
            "area": round(area, 3),
            "max_rate": round(rate, 3),
            "shape_seed": shape_seed,
        }
        # the shape (hence its bounding radius) does not depend on the rate: preview it uncalibrated
        br = DeformingStar.random(
            np.random.default_rng(shape_seed), (0.0, 0.0), area, max_rate=rate, calibrate=False
        ).bounding_radius
        c = np.asarray(spec["centre"], dtype=float)
        if min(np.hypot(*(c - start)), np.hypot(*(c - goal))) - br < 1.5:
            continue
        if any(np.hypot(*(c - pc)) - br - pr < gap for pc, pr in placed):
            continue
        placed.append((c, br))
        specs.append(spec)
    if len(specs) < n:
        raise PlacementError(f"random-ch4:{seed}", len(specs), n, f"{_MORE_TRIES * n} draws")
    description = f"random Chapter-4 scene {seed}: {len(specs)} deforming obstacles"
    return _generated(f"random-ch4:{seed}", description, 60.0, specs, noise_std, dropout)


def _generated(name: str, description: str, t_max: float, specs: list[dict[str, Any]],
               noise_std: float, dropout: float) -> Uuv2dScenario:  # fmt: skip
    """A generated Chapter-4 scene ``name``: the thesis's vehicle (start, goal, limits, radius),
    the sonar's noise ``noise_std`` and ``dropout``, and the obstacles ``specs``."""
    data = {
        "kind": "uuv2d",
        "name": name,
        "description": description,
        "t_max": t_max,
        "vehicle": {
            "start": list(CH4_START),
            "goal": list(CH4_GOAL),
            "v_max": CH4_V_MAX,
            "u_max": CH4_U_MAX,
            "radius": CH4_RADIUS,
        },
        "sonar": {"noise_std": noise_std, "dropout": dropout},
        "obstacles": specs,
    }
    return uuv2d_from_dict(data, name)


def _closest_approach(p: np.ndarray, v: np.ndarray, horizon: float) -> float:
    """Smallest |p + v t| [m] over t in [0, horizon] (relative position p, relative velocity v)."""
    vv = float(v @ v)
    t = 0.0 if vv == 0.0 else min(max(-float(p @ v) / vv, 0.0), horizon)
    return float(np.hypot(*(p + v * t)))


#: bounds of the harder family (:func:`random_ch4_hard_scenario`)
HARD_RATE = (0.3, 0.6)  # deformation rate bound [m/s]: up to 0.6 V_max
HARD_SPEED = 0.3  # largest translation speed of a mass centre [m/s]
HARD_GAP_MARGIN = 0.05  # bounding discs at least 2 (radius + this) apart [m]
HARD_T_MAX = 30.0  # time limit [s] (the straight run takes 10 s); every check covers it


def _hard_round(
    rng: np.random.Generator, n: int, rate: tuple[float, float], speed_max: float
) -> list[dict[str, Any]]:
    """One placement of :func:`random_ch4_hard_scenario`'s bodies: up to ``n`` bodies in
    ``40 n`` draws from ``rng`` (fewer when the first placed leave no room)."""
    horizon = HARD_T_MAX
    start = np.array(CH4_START)
    goal = np.array(CH4_GOAL)
    u = (goal - start) / np.hypot(*(goal - start))
    normal = np.array([-u[1], u[0]])
    gap = 2.0 * (CH4_RADIUS + HARD_GAP_MARGIN)
    cruise = math.sqrt(2.0) * CH4_V_MAX
    placed: list[tuple[np.ndarray, np.ndarray, float]] = []
    specs: list[dict[str, Any]] = []
    for _ in range(40 * n):
        if len(specs) == n:
            break
        area = float(rng.uniform(0.5, 4.0))
        shape_seed = int(rng.integers(0, 2**31 - 1))
        body_rate = float(rng.uniform(*rate))
        br = DeformingStar.random(
            np.random.default_rng(shape_seed), (0.0, 0.0), area, max_rate=body_rate, calibrate=False
        ).bounding_radius
        for _ in range(25):  # places for this body (its bounding radius is costly to compute)
            along = float(rng.uniform(2.5, 11.6))
            lateral = float(rng.uniform(-0.3, 0.3)) if not specs else float(rng.uniform(-1.5, 1.5))
            speed = 0.0 if not specs else float(rng.uniform(0.0, speed_max))
            # across the line (within 45 degrees of its normal), either way
            tilt = float(rng.uniform(-math.pi / 4, math.pi / 4))
            side = 1.0 if rng.random() < 0.5 else -1.0
            direction = side * (math.cos(tilt) * normal + math.sin(tilt) * u)
            vel = np.round(speed * direction, 3) + 0.0  # + 0.0: no negative zeros
            # where it is when the vehicle passes `along` is `lateral` off the line
            c = np.round(start + along * u + lateral * normal - vel * (along / cruise), 3)
            clear_ends = min(
                _closest_approach(c - start, vel, horizon),
                _closest_approach(c - goal, vel, horizon),
            )
            if clear_ends - br < 1.0:
                continue
            if any(_closest_approach(c - pc, vel - pv, horizon) - br - pr < gap
                   for pc, pv, pr in placed):  # fmt: skip
                continue
            placed.append((c, vel, br))
            specs.append(
                {
                    "type": "deforming",
                    "centre": [float(c[0]), float(c[1])],
                    "area": round(area, 3),
                    "max_rate": round(body_rate, 3),
                    "shape_seed": shape_seed,
                    "velocity": [float(vel[0]), float(vel[1])],
                }
            )
            break
    return specs


@typed_generator("random-ch4-hard")
def random_ch4_hard_scenario(
    seed: int,
    *,
    n_obstacles: Annotated[
        int | None, Field(ge=2, le=10, description="number of bodies (drawn in 2..6 when null)")
    ] = None,
    noise_std: Annotated[float, Field(ge=0, description="sonar range noise [m]")] = 0.0,
    dropout: Annotated[float, Field(ge=0, le=1, description="sonar dropout probability")] = 0.0,
    rate: Annotated[
        RateRange, Field(description="range of the deformation rate bound [m/s]")
    ] = HARD_RATE,
    speed_max: Annotated[
        float,
        Field(ge=0, lt=CH4_V_MAX, description="largest mass-centre speed [m/s]; rate max + this "
              "must stay below V_max"),
    ] = HARD_SPEED,
) -> Uuv2dScenario:  # fmt: skip
    """A harder random Chapter-4 scene: faster, translating bodies, narrow gaps (seeded).

    ``random-ch4-hard:<seed>``, still within the chapter's assumptions as
    :func:`random_ch4_scenario` reads them.

    What is harder: 2-6 bodies; deformation at the top of the rate range (boundary speed bound
    drawn from ``HARD_RATE`` = 0.3-0.6 m/s, against 0.05-0.3 m/s); every body but possibly the
    first translates (mass-centre speed up to ``HARD_SPEED`` = 0.3 m/s) roughly *across* the I-E
    line, timed to cross it near when the vehicle (sqrt(2) V_max along the diagonal) gets there;
    and the bounding discs of two bodies may come as close as 2 (vehicle radius + 0.05 m) — a gap
    the vehicle fits through with 5 cm on each side — instead of 2 (radius + 0.3 m).

    Assumptions kept (the chapter's): each body is one star-shaped, closed, smooth outline of fixed
    area whose mass centre is known to the vehicle (§4.2); its boundary moves slower than the
    vehicle (deformation rate + translation speed <= 0.9 m/s < V_max = 1 m/s per component);
    bodies never touch one another (the closest approach of their bounding discs over the whole
    episode, t_max = ``HARD_T_MAX`` = 30 s, computed from their constant velocities, is at least
    the gap above, so no two bodies merge into a non-star body with a narrow inner space,
    Fig. 4.2(b)); I and E stay clear (every bounding disc stays 1.0 m from both over t_max); at
    least one body starts across the I-E line.  The time limit is 30 s (3 times the straight
    run): a translating body may drift onto E after that.

    ``rate`` and ``speed_max`` widen the family up to the edge of the chapter's assumption: the
    boundary's speed bound, deformation rate + translation speed, stays below V_max.

    Args:
        seed: scene number.

    Raises:
        ScenarioError: a parameter out of range (one line).
        PlacementError: the bodies drawn cannot all be placed.
    """
    source = f"random-ch4-hard:{seed}"
    if not rate[1] + speed_max < CH4_V_MAX:
        raise ScenarioError(
            source, "params.speed_max", f"rate max + speed_max = {rate[1] + speed_max:g} m/s is "
            f"not below V_max = {CH4_V_MAX:g} m/s (the chapter's assumption)",
        )  # fmt: skip
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7)) if n_obstacles is None else int(n_obstacles)
    specs = _hard_round(rng, n, rate, speed_max)
    best = len(specs)
    for _ in range(_RETRY_ROUNDS):  # only a scene the family's own draws leave short
        if len(specs) == n:
            break
        specs = _hard_round(rng, n, rate, speed_max)
        best = max(best, len(specs))
    if len(specs) < n:
        raise PlacementError(
            source, best, n, f"{1 + _RETRY_ROUNDS} placements of {40 * n} draws each"
        )
    description = (
        f"harder random Chapter-4 scene {seed}: {len(specs)} deforming obstacles, fast "
        "deformation, translating, narrow gaps"
    )
    return _generated(f"random-ch4-hard:{seed}", description, HARD_T_MAX, specs, noise_std,
                      dropout)  # fmt: skip


#: Seeded Chapter-4 scene generators by name (``load_uuv2d_scenario("random-ch4:7")``).
UUV2D_GENERATORS: dict[str, Callable[..., Uuv2dScenario]] = {
    "random-ch4": random_ch4_scenario,
    "random-ch4-hard": random_ch4_hard_scenario,
}
