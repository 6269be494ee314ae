"""Chapter 5 scenarios: the 3D underwater vehicle with the sonar array among shape-changing bodies.

Thesis Chapter 5 §5.2.4, Fig. 5.3 (Y. Zhang and J. Zhang, ICCAE 2022): start A and end B known and
fixed; obstacles with smooth boundaries, fixed mass centres and shapes that change "in some
extent".  Scene 1 (Fig. 5.3(a)): one ordinary obstacle deforming by at most 10 %.  Scene 2
(Fig. 5.3(b)): an obstacle with "a really narrow space inside" that the robot is wider than.
Scene 3 (Fig. 5.3(c)): two obstacles on the way.  The thesis gives no coordinates (its figures are
bird's-eye sketches); the built-ins (``uvnav/scenarios/builtin/ch5/*.yaml``) place A and B 26-30 m
apart with the obstacles across the straight line, sized for a vehicle of hull radius 0.5 m.

The schema is a separate pydantic model (``extra="forbid"``) beside the 2D one; errors are one
line ``<file>: <field>: <problem>`` (:class:`~uvnav.scenarios.errors.ScenarioError`).  Random
scenes come from :func:`random_ch5_scenario` (``random-ch5:<seed>``): 1-3 deforming stars
straddling the A-B line, within the assumptions the law needs (listed in its docstring).
"""

from __future__ import annotations

import itertools
import math
from functools import cache, partial
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, ValidationError, model_validator

from uvnav.dynamics.vehicle3d import Vehicle3DSpec
from uvnav.obstacles.deforming3d import CompoundBody, as_compound, horseshoe, random_star
from uvnav.scenarios.errors import FieldError, ScenarioError, from_validation_error
from uvnav.scenarios.limits import BoundedScene, FileModel, check_timing
from uvnav.scenarios.loader import builtin_yaml_files, parse_yaml
from uvnav.scenarios.params import typed_generator
from uvnav.sensors.sonar_array import SonarArray
from uvnav.sim.episode_uuv3d import UUV3DSetup

BUILTIN_SUBDIR = "ch5"  # of the built-in scenario folder
GENERATOR_CH5 = "random-ch5"
GENERATOR_CH5_DENSE = "random-ch5-dense"  # beyond the assumptions: bodies closer than the law needs

Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Pos = Annotated[float, Field(gt=0)]


_Model = FileModel


class Robot5(_Model):
    """Vehicle: start A, unit-able heading, end B [m]; limits V_max [m/s], U_max [rad/s]; hull
    radius [m]."""

    start: Vec3
    heading: Vec3
    goal: Vec3
    v_max: Pos = 1.0
    u_max: Pos = 1.0
    radius: Pos = 0.5

    @model_validator(mode="after")
    def _heading_nonzero(self) -> Robot5:
        if float(np.linalg.norm(self.heading)) < 1e-9:
            raise ValueError("heading must be a non-zero vector")
        return self


class Sonar5(_Model):
    """Sonar array: ring polar angle and beam half-angle [deg], max range [m], noise [m],
    dropout probability."""

    ring_angle_deg: Annotated[float, Field(gt=0, lt=90)] = 35.0
    half_angle_deg: Annotated[float, Field(gt=0, lt=90)] = 20.0
    max_range: Pos = 8.0
    noise_std: Annotated[float, Field(ge=0)] = 0.0
    dropout: Annotated[float, Field(ge=0, le=1)] = 0.0


class Star5(_Model):
    """A deforming star: centre [m], base radius [m], reference-shape size and deformation bound
    (thesis: <= 0.1), frequencies up to ``max_frequency`` [rad/s], drawn from ``seed``."""

    type: Literal["star"] = "star"
    centre: Vec3
    base_radius: Pos
    shape_scale: Annotated[float, Field(ge=0, lt=1)] = 0.3
    delta_max: Annotated[float, Field(ge=0, le=0.1)] = 0.1
    max_frequency: Annotated[float, Field(ge=0)] = 0.5
    seed: Annotated[int, Field(ge=0)] = 0


class Horseshoe5(_Model):
    """Scene 2's U-shaped body: centre [m], slot width [m], arm length/thickness and height [m],
    yaw of the slot opening [deg], deformation bound, frequency [rad/s]."""

    type: Literal["horseshoe"]
    centre: Vec3
    slot_width: Pos
    arm_length: Pos = 3.0
    arm_thickness: Pos = 1.0
    height: Pos = 2.5
    yaw_deg: float = 0.0
    delta_max: Annotated[float, Field(ge=0, le=0.1)] = 0.05
    frequency: Annotated[float, Field(ge=0)] = 0.3


Obstacle5Spec = Annotated[Star5 | Horseshoe5, Field(discriminator="type")]


class Controller5(_Model):
    """Law name, locator (``geometric`` min/argmin, ``network`` trained BPNN, ``oracle``
    true nearest point) and its parameters."""

    name: Literal["zhang2022-uuv3d-v1"] = "zhang2022-uuv3d-v1"
    locator: Literal["geometric", "network", "oracle"] = "geometric"
    params: dict[str, float] = Field(default_factory=dict)


class Scenario5(BoundedScene):
    """A Chapter 5 scenario (module docstring)."""

    name: str
    description: str = ""
    dim: Literal[3] = 3
    dt: Pos = 0.05
    control_period: Pos = 0.2
    t_max: Pos = 90.0
    goal_tolerance: Pos = 0.5
    subdivisions: Annotated[int, Field(ge=1, le=4)] = 2
    robot: Robot5
    sonar: Sonar5 = Sonar5()
    obstacles: list[Obstacle5Spec] = Field(default_factory=list)
    controller: Controller5 = Controller5()

    @model_validator(mode="after")
    def _consistent(self) -> Scenario5:
        check_timing(self.t_max, self.dt, self.control_period)
        r = self.robot
        start, goal = np.asarray(r.start, float), np.asarray(r.goal, float)
        if float(np.linalg.norm(goal - start)) <= self.goal_tolerance:
            raise FieldError(
                "robot.goal", f"is within goal_tolerance={self.goal_tolerance:g} m of the start"
            )
        for j, body in enumerate(build_obstacles(self)):
            if bool(body.contains(goal, 0.0)[0]):
                raise FieldError("robot.goal", f"lies inside obstacle {j} at t=0")
            inside = bool(body.contains(start, 0.0)[0])
            if inside or body.nearest(start, 0.0)[1] < r.radius:
                raise FieldError(
                    "robot.start",
                    f"vehicle (radius {r.radius:g} m) overlaps obstacle {j} at t=0",
                )
        return self


def scenario5_from_dict(data: dict[str, Any], source: str = "<dict>") -> Scenario5:
    """Validate a mapping as a :class:`Scenario5`.

    Raises:
        ScenarioError: one line naming the source, the field and the problem.
    """
    try:
        return Scenario5.model_validate(data)
    except ValidationError as exc:
        err = from_validation_error(exc, source)
        # drop the union-tag segment pydantic puts in the path (obstacles.0.star.x -> obstacles.0.x)
        path = ".".join(p for p in err.path.split(".") if p not in ("star", "horseshoe"))
        raise ScenarioError(err.source, path, err.problem) from None


def _builtin_files() -> dict[str, Any]:
    return builtin_yaml_files(BUILTIN_SUBDIR)


def list_ch5_builtin() -> list[str]:
    """Names of the built-in Chapter 5 scenarios, sorted."""
    return sorted(_builtin_files())


@cache
def _load_builtin(name: str) -> Scenario5:
    f = _builtin_files()[name]
    return scenario5_from_dict(parse_yaml(f.read_text(), f"{name}.yaml"), f"{name}.yaml")


def load_ch5_scenario(name: str) -> Scenario5:
    """A built-in name, a ``random-ch5:<seed>`` or ``random-ch5-dense:<seed>`` spec or a YAML
    path.

    Raises:
        ScenarioError: unknown name, unreadable file or invalid content (one line).
    """
    for generator in (GENERATOR_CH5, GENERATOR_CH5_DENSE):
        if name.startswith(generator + ":"):
            seed_text = name.split(":", 1)[1]
            if not seed_text.isdigit():
                raise ScenarioError(
                    name, "seed", f"must be a non-negative integer (got {seed_text!r})"
                )
            return CH5_GENERATORS[generator](int(seed_text))
    if name in _builtin_files():
        return _load_builtin(name)
    path = Path(name)
    if not path.is_file():
        known = ", ".join(list_ch5_builtin())
        raise ScenarioError(name, "", f"no such file or Chapter 5 scenario (built-in: {known})")
    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise ScenarioError(str(path), "", "is not a text (YAML) file") from None
    except OSError as exc:
        raise ScenarioError(str(path), "", f"cannot be read ({exc.strerror or exc})") from None
    return scenario5_from_dict(parse_yaml(text, str(path)), str(path))


def build_obstacles(scn: Scenario5) -> tuple[CompoundBody, ...]:
    """The scenario's obstacles as bodies (stars drawn from their seeds)."""
    out: list[CompoundBody] = []
    for ob in scn.obstacles:
        if isinstance(ob, Star5):
            star = random_star(
                np.random.default_rng(ob.seed),
                np.asarray(ob.centre, float),
                ob.base_radius,
                shape_scale=ob.shape_scale,
                delta_max=ob.delta_max,
                max_frequency=ob.max_frequency,
                subdivisions=scn.subdivisions,
            )
            out.append(as_compound(star))
        else:
            out.append(
                horseshoe(
                    np.asarray(ob.centre, float),
                    slot_width=ob.slot_width,
                    arm_length=ob.arm_length,
                    arm_thickness=ob.arm_thickness,
                    height=ob.height,
                    yaw=math.radians(ob.yaw_deg),
                    delta_max=ob.delta_max,
                    frequency=ob.frequency,
                    subdivisions=scn.subdivisions,
                )
            )
    return tuple(out)


def build_uuv3d(scn: Scenario5, *, noise_std: float | None = None) -> UUV3DSetup:
    """The simulator setup of a scenario (``noise_std`` overrides the sonar noise [m])."""
    r = scn.robot
    s = scn.sonar
    array = SonarArray(
        hull_radius=r.radius,
        ring_angle=math.radians(s.ring_angle_deg),
        half_angle=math.radians(s.half_angle_deg),
        max_range=s.max_range,
        noise_std=s.noise_std if noise_std is None else noise_std,
        dropout=s.dropout,
    )
    head = np.asarray(r.heading, float)
    return UUV3DSetup(
        start=np.asarray(r.start, float),
        heading=head / np.linalg.norm(head),
        goal=np.asarray(r.goal, float),
        spec=Vehicle3DSpec(r.v_max, r.u_max, r.radius),
        obstacles=build_obstacles(scn),
        array=array,
        dt=scn.dt,
        control_period=scn.control_period,
        t_max=scn.t_max,
        goal_tolerance=scn.goal_tolerance,
    )


#: version of the ``random-ch5`` generator; part of the campaign's resume key, so that a store
#: written by an older generator is not mistaken for the current scenes.  v1 asked for 1-3 bodies
#: but its fixed 12 m spacing never fitted a third; v2 spaces bodies by their size and lengthens
#: the A-B line when they do not fit, so every drawn count is built.
RANDOM_CH5_VERSION = 2
#: largest growth of a body's centre distance under deformation (thesis: 10 %)
_DEFORM = 1.1


def random_ch5_min_spacing(
    r_a: float, r_b: float, hull_radius: float = 0.5, *, dense: bool = False
) -> float:
    """Smallest centre-to-centre distance [m] of two consecutive bodies of base radii ``r_a``,
    ``r_b`` [m] in a ``random-ch5`` scene: their deformed radii (x1.1), the vehicle's width
    (2 rho), the switch distance L = 3 m and one turn radius V_max/U_max = 1 m — so the vehicle
    can finish one avoidance before the next body is within L (the law evades one point at a
    time; thesis §5.3).  ``dense`` (``random-ch5-dense``, beyond the assumptions): the deformed
    radii, the vehicle's width and 1 m only, so the next body is within L while one avoidance is
    still under way."""
    if dense:
        return _DEFORM * (r_a + r_b) + 2.0 * hull_radius + 1.0
    return _DEFORM * (r_a + r_b) + 2.0 * hull_radius + 3.0 + 1.0


def random_ch5_end_clearance(r0: float) -> float:
    """Smallest distance [m] from A or B to the centre of a body of base radius ``r0`` [m]:
    5 m (the switch distance L = 3 m plus the turn) plus 1.4 radii."""
    return 5.0 + 1.4 * r0


def random_ch5_scenario(
    seed: int,
    *,
    n_obstacles: Annotated[
        int | None, Field(description="number of bodies, 1..3 (2..4 dense; drawn when null)")
    ] = None,
    locator: Annotated[
        Literal["geometric", "network", "oracle"],
        Field(description="the scene's locator (the law's default)"),
    ] = "geometric",
    noise_std: Annotated[
        float, Field(ge=0, allow_inf_nan=False, description="sonar range noise std [m]")
    ] = 0.0,
    dense: bool = False,
) -> Scenario5:
    """A random scene within the assumptions of the Chapter 5 law (seeded; generator v2).

    ``dense=True`` (``random-ch5-dense:<seed>``) is a harder family *beyond* those assumptions,
    to measure how the law degrades: 2-4 bodies spaced by :func:`random_ch5_min_spacing` with
    ``dense`` (the next body is within the switch distance before one avoidance ends).

    A = origin, heading toward B; B at least 26-32 m away in a random direction up to 30 deg
    from horizontal.  1-3 deforming stars (base radius 1-2.2 m, deformation <= 10 %), each
    offset sideways from the A-B line by at most its radius (so it blocks the straight line).
    Consecutive centres lie at least :func:`random_ch5_min_spacing` apart along the line (7.2-
    9.8 m), the first and last at least :func:`random_ch5_end_clearance` from A and B; when the
    drawn bodies do not fit on the drawn line, the line is lengthened to fit them plus 2 m, and
    the free length is spread at random between the gaps.  Every drawn count is thus built and
    no scene is filtered after the fact.

    Raises:
        ScenarioError: ``n_obstacles`` outside 1..3 (2..4 with ``dense``).
    """
    rng = np.random.default_rng(seed)
    lo, hi = (2, 4) if dense else (1, 3)
    generator = GENERATOR_CH5_DENSE if dense else GENERATOR_CH5
    n = int(n_obstacles) if n_obstacles is not None else int(rng.integers(lo, hi + 1))
    if not lo <= n <= hi:
        raise ScenarioError(
            f"{generator}:{seed}", "params.n_obstacles", f"must be in {lo}..{hi} (got {n})"
        )
    dist = float(rng.uniform(26.0, 32.0))
    az = float(rng.uniform(0, 2 * math.pi))
    el = float(rng.uniform(-math.pi / 6, math.pi / 6))
    d = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    radii = [float(rng.uniform(1.0, 2.2)) for _ in range(n)]
    gaps = [random_ch5_end_clearance(radii[0])]
    gaps += [random_ch5_min_spacing(a, b, dense=dense) for a, b in itertools.pairwise(radii)]
    gaps.append(random_ch5_end_clearance(radii[-1]))
    dist = max(dist, sum(gaps) + 2.0)
    # the free length, split at n uniform cut points into n + 1 random shares
    shares = np.diff(np.concatenate([[0.0], np.sort(rng.uniform(size=n)), [1.0]]))
    free = dist - sum(gaps)
    goal = d * dist
    obstacles: list[dict[str, Any]] = []
    s = 0.0
    for k, r0 in enumerate(radii):
        s += gaps[k] + float(shares[k]) * free
        side = rng.normal(size=3)
        side -= float(side @ d) * d
        side /= np.linalg.norm(side)
        c = d * s + side * float(rng.uniform(0, r0))
        obstacles.append(
            {
                "type": "star",
                "centre": [float(x) for x in c],
                "base_radius": r0,
                "shape_scale": float(rng.uniform(0.0, 0.35)),
                "delta_max": 0.1,
                "max_frequency": 0.5,
                "seed": int(rng.integers(0, 2**31)),
            }
        )
    data = {
        "name": f"{generator}:{seed}",
        "description": (
            f"random Ch. 5 scene: {len(obstacles)} deforming bodies between A and B"
            + (", closer than the law needs (beyond the assumptions)" if dense else "")
        ),
        "t_max": 120.0,
        "sonar": {"noise_std": noise_std},
        "robot": {
            "start": [0.0, 0.0, 0.0],
            "heading": [float(x) for x in d],
            "goal": [float(x) for x in goal],
        },
        "obstacles": obstacles,
        "controller": {"locator": locator},
    }
    return scenario5_from_dict(data, f"{generator}:{seed}")


#: the Chapter 5 seed generators, ``f(seed, **params)`` with typed parameters
CH5_GENERATORS: dict[str, Any] = {
    name: typed_generator(name)(partial(random_ch5_scenario, dense=name == GENERATOR_CH5_DENSE))
    for name in (GENERATOR_CH5, GENERATOR_CH5_DENSE)
}
