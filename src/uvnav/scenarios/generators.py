"""Seeded generators of random scenarios.

:func:`random_ch2_scenario` draws scenes of the kind the thesis's Chapter 2 experiments use
(Figs. 2.7-2.8): the robot goes from I = [0, 0] to T = [10, 10] with V_max = 0.707 m/s and
U_max = 1.414 rad/s among randomly wandering non-convex obstacles that lie in its way and obey the
motion constraints (2.6)-(2.8).  Shapes and motions are drawn by rejection: a candidate is redrawn
until it is a valid, star-shaped, non-convex polygon and satisfies
:func:`uvnav.scenarios.build.check_constraints`; a position is redrawn until it keeps the required
clearances.  Everything is drawn from ``np.random.default_rng(seed)``, so a seed always gives the
same scene.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, ValidationError

from uvnav.geometry.polygons import cyclic_next, cyclic_prev, polygon_area, polygon_centroid
from uvnav.scenarios.build import obstacle_bounds
from uvnav.scenarios.crowd_dynamic import crowd_dynamic_scenario
from uvnav.scenarios.crowdnav import crowdnav_circle, crowdnav_square
from uvnav.scenarios.errors import PlacementError, ScenarioError, from_validation_error
from uvnav.scenarios.generators3d import random_ch3_scenario
from uvnav.scenarios.params import generator_variant, typed_generator
from uvnav.scenarios.parse import scenario_from_dict
from uvnav.scenarios.pedestrians import (
    FORMATS,
    all_positions,
    episode_tracks,
    load_tracks,
    walkway_axes,
)
from uvnav.scenarios.schema import CrowdSpec, ObstacleSpec, Scenario

CH2_START = (0.0, 0.0)
CH2_GOAL = (10.0, 10.0)
CH2_V_MAX = 0.707  # [m/s]
CH2_U_MAX = 1.414  # [rad/s]
CH2_ARENA = (-3.0, -3.0, 13.0, 13.0)  # [m]

_RADIUS_RANGE = (0.3, 0.9)  # vertex distance from the centroid [m]
_VERTEX_COUNT = (5, 9)
_ALONG_TRACK = (2.0, 12.0)  # [m] from I along I->T
_LATERAL = 2.0  # [m] either side of the I->T line
_END_CLEARANCE = 1.5  # [m] from start and goal to the obstacle's bounding disc
_GAP = 0.3  # [m] between bounding discs of two obstacles
_MAX_TRIES = 500


def is_convex(vertices: np.ndarray) -> bool:
    """True when the simple polygon ``vertices`` (n, 2) has no reflex vertex."""
    v = np.asarray(vertices, dtype=float)
    if polygon_area(v) < 0:
        v = v[::-1]
    e_in = v - cyclic_prev(v)
    e_out = cyclic_next(v) - v
    cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]
    return bool(np.all(cross >= -1e-12))


def is_star_about(vertices: np.ndarray, point: np.ndarray) -> bool:
    """True when every edge of the CCW polygon ``vertices`` is seen from ``point`` turning CCW.

    For vertices listed in angular order about ``point``, this is the condition for the polygon to
    be star-shaped with respect to ``point`` (every ray from it crosses the boundary once).
    """
    rel = np.asarray(vertices, dtype=float) - point
    nxt = cyclic_next(rel)
    return bool(np.all(rel[:, 0] * nxt[:, 1] - rel[:, 1] * nxt[:, 0] > 1e-9))


def random_star_polygon(
    rng: np.random.Generator,
    *,
    n_vertices: tuple[int, int] = _VERTEX_COUNT,
    radii: tuple[float, float] = _RADIUS_RANGE,
) -> np.ndarray:
    """A random non-convex polygon, star-shaped about its own centroid, centred on it.

    Args:
        rng: generator.
        n_vertices: inclusive range of the vertex count.
        radii: range of vertex distances from the centroid [m].

    Returns:
        (n, 2) counter-clockwise vertices [m], centroid at the origin (to 1e-4 m).
    """
    from shapely.geometry import Polygon

    for _ in range(_MAX_TRIES):
        k = int(rng.integers(n_vertices[0], n_vertices[1] + 1))
        step = 2.0 * math.pi / k
        angles = (
            step * np.arange(k) + rng.uniform(0.0, 2.0 * math.pi) + rng.uniform(-0.3, 0.3, k) * step
        )
        r = rng.uniform(radii[0], radii[1], k)
        verts = np.stack([r * np.cos(angles), r * np.sin(angles)], axis=-1)
        verts = np.round(verts - polygon_centroid(verts), 4)
        c = polygon_centroid(verts)
        dist = np.hypot(*(verts - c).T)
        if dist.min() < radii[0] or dist.max() > radii[1]:
            continue
        if is_convex(verts) or not is_star_about(verts, c) or not Polygon(verts).is_valid:
            continue
        return verts
    raise RuntimeError("could not draw a star-shaped non-convex polygon")  # pragma: no cover


#: defaults of :func:`random_ch2_scenario`'s envelope (the family as it always was)
CH2_SPEED_RATIO = 0.5  # largest obstacle speed / V_max
CH2_TURN_RATIO = 0.3 / CH2_U_MAX  # largest course turn rate / U_max (0.3 rad/s; 0.21 U_max)
#: ``random-ch2-edge``: random-ch2 at the edge of (2.6)-(2.7): 8 fast, fast-turning
#: discs (discs: a polygon that fast and turning that fast breaks (2.8))
CH2_EDGE: dict[str, Any] = {
    "n_obstacles": 8,
    "speed_ratio_max": 0.95,
    "turn_rate_ratio_max": 0.95,
    "body": "disc",
}
#: crowd id of the bodies that avoid each other (``mutual_avoidance``)
CH2_AVOID_CROWD = "bodies"


def _random_motion(
    rng: np.random.Generator,
    v_hi: float = CH2_SPEED_RATIO * CH2_V_MAX,
    w_hi: float = CH2_TURN_RATIO * CH2_U_MAX,
    avoid: bool = False,
) -> dict[str, Any]:
    """A ``random_turn`` motion (``orca_wander`` with ``avoid``): speeds within [lo, hi] with lo
    in [0.05, min(0.2, v_hi)] and hi in [lo, v_hi] [m/s], turn rates within +-w, w in
    [0.05, w_hi] [rad/s].  The defaults draw exactly what the family always drew."""
    lo = float(rng.uniform(0.05, min(0.2, v_hi)))
    hi = float(rng.uniform(lo, v_hi))
    w = float(rng.uniform(0.05, w_hi))
    motion: dict[str, Any] = {
        "type": "orca_wander" if avoid else "random_turn",
        "speed": [round(lo, 4), round(hi, 4)],
        "turn_rate": [round(-w, 4), round(w, 4)],
        "change_period": round(float(rng.uniform(1.0, 3.0)), 3),
        "arena": list(CH2_ARENA),
    }
    if avoid:
        motion["crowd"] = CH2_AVOID_CROWD
    return motion


def _random_body(rng: np.random.Generator, body: str) -> tuple[dict[str, Any], float]:
    """A body spec and its bounding radius [m]: a star polygon, or a disc of radius 0.3-0.9 m."""
    if body == "disc":
        r = round(float(rng.uniform(*_RADIUS_RANGE)), 3)
        return {"disc": r}, r
    verts = random_star_polygon(rng)
    return {"polygon": verts.tolist()}, float(
        np.max(np.hypot(*(verts - polygon_centroid(verts)).T))
    )


def _place_centre(
    rng: np.random.Generator,
    bound: float,
    placed: list[tuple[np.ndarray, float]],
    start: np.ndarray,
    goal: np.ndarray,
) -> np.ndarray | None:
    """A centre near the I->T line clear of I, T and the placed bodies, or ``None``."""
    along = (goal - start) / np.hypot(*(goal - start))
    across = np.array([-along[1], along[0]])
    for _ in range(_MAX_TRIES):
        c = start + rng.uniform(*_ALONG_TRACK) * along + rng.uniform(-_LATERAL, _LATERAL) * across
        c = np.round(c, 3)
        if np.hypot(*(c - start)) - bound < _END_CLEARANCE:
            continue
        if np.hypot(*(c - goal)) - bound < _END_CLEARANCE:
            continue
        if any(np.hypot(*(c - pc)) < bound + pb + _GAP for pc, pb in placed):
            continue
        return c
    return None


def _ch2_obstacles(
    rng: np.random.Generator, n: int, source: str, *, v_hi: float, w_hi: float, body: str,
    avoid: bool,
) -> list[dict[str, Any]]:  # fmt: skip
    """``n`` obstacles of :func:`random_ch2_scenario` drawn from ``rng``.

    Raises:
        PlacementError: a body that obeys (2.6)-(2.8) and fits could not be drawn.
    """
    start, goal = np.asarray(CH2_START), np.asarray(CH2_GOAL)
    obstacles: list[dict[str, Any]] = []
    placed: list[tuple[np.ndarray, float]] = []  # (centre, bounding radius)
    for j in range(n):
        for _ in range(_MAX_TRIES):
            shape, bound = _random_body(rng, body)
            spec: dict[str, Any] = {
                "name": f"{'disc' if body == 'disc' else 'polygon'}-{j}",
                "body": shape,
                "start": {"position": [0.0, 0.0], "heading": 0.0},
                "motion": _random_motion(rng, v_hi, w_hi, avoid),
            }
            speed, turn, growth = obstacle_bounds(ObstacleSpec.model_validate(spec))
            if not (speed < CH2_V_MAX and turn < CH2_U_MAX and growth < CH2_V_MAX - speed):
                continue
            centre = _place_centre(rng, bound, placed, start, goal)
            if centre is None:
                continue
            heading = round(float(rng.uniform(-math.pi, math.pi)), 4)
            spec["start"] = {"position": centre.tolist(), "heading": heading}
            placed.append((centre, bound))
            obstacles.append(spec)
            break
        else:
            raise PlacementError(
                source,
                j,
                n,
                f"no clear place for body {j} that obeys (2.6)-(2.8) in {_MAX_TRIES} draws",
            )
    return obstacles


@typed_generator("random-ch2")
def random_ch2_scenario(
    seed: int,
    *,
    n_obstacles: Annotated[
        int | None, Field(ge=0, le=30, description="number of bodies (drawn in 1..6 when null)")
    ] = None,
    speed_ratio_max: Annotated[
        float,
        Field(ge=0.1, lt=1.0, description="largest body speed / V_max ((2.6): below 1)"),
    ] = CH2_SPEED_RATIO,
    turn_rate_ratio_max: Annotated[
        float,
        Field(ge=0.05, lt=1.0, description="largest course turn rate / U_max ((2.7): below 1)"),
    ] = CH2_TURN_RATIO,
    body: Annotated[
        Literal["polygon", "disc"],
        Field(description="non-convex star polygons, or discs (no (2.8) growth: fast bodies)"),
    ] = "polygon",
    mutual_avoidance: Annotated[
        bool,
        Field(description="bodies steer around each other (ORCA, motion orca_wander)"),
    ] = False,
    controller: Annotated[str, Field(description="default law of the scene")] = "zhang2019-v1",
    controller_params: Annotated[dict[str, Any] | None, Field(description="its parameters")] = None,
    dt: Annotated[float, Field(gt=0, description="integration and decision step [s]")] = 0.1,
    t_max: Annotated[float, Field(gt=0, description="time limit [s]")] = 120.0,
) -> Scenario:
    """A random Chapter-2 scene, deterministic in ``seed``.

    Robot: I = [0, 0], T = [10, 10], heading toward T, V_max 0.707 m/s, U_max 1.414 rad/s, radius
    0.1 m.  Obstacles (defaults): non-convex star-shaped polygons (5-9 vertices at 0.3-0.9 m from
    the centroid) centred near the I->T line (2-12 m along it, up to +-2 m across), clear of each
    other (0.3 m between bounding discs) and of the start and goal (1.5 m from the bounding disc),
    moving with ``random_turn`` (speeds within [0.05, 0.5 V_max] m/s, turn rates within +-0.3
    rad/s, arena [-3, -3, 13, 13] m) and obeying the thesis's (2.6)-(2.8): a drawn body that does
    not is redrawn.

    The parameters widen the family up to the edge of (2.6)-(2.7): the largest speed is
    ``speed_ratio_max`` V_max, the largest turn rate ``turn_rate_ratio_max`` U_max (with
    polygons, (2.8) then rejects the fast, fast-turning draws; discs have no rotation growth);
    ``mutual_avoidance`` drives the bodies as one ORCA crowd whose preferred velocities wander as
    ``random_turn`` does (motion ``orca_wander``: their bounding discs avoid each other, the
    bodies do not rotate).  The defaults draw exactly the scenes the family always drew.

    Args:
        seed: the only source of randomness.

    Raises:
        ScenarioError: a parameter out of range (one line).
        PlacementError: the bodies drawn cannot all be placed (e.g. too many for the strip).
    """
    source = f"random-ch2:{seed}"
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 7)) if n_obstacles is None else int(n_obstacles)
    obstacles = _ch2_obstacles(
        rng, n, source, v_hi=speed_ratio_max * CH2_V_MAX, w_hi=turn_rate_ratio_max * CH2_U_MAX,
        body=body, avoid=mutual_avoidance,
    )  # fmt: skip
    start = np.asarray(CH2_START)
    goal = np.asarray(CH2_GOAL)
    along = (goal - start) / np.hypot(*(goal - start))
    heading = float(np.arctan2(along[1], along[0]))
    data: dict[str, Any] = {
        "name": f"random-ch2-{seed}",
        "description": _ch2_description(
            seed, n, speed_ratio_max, turn_rate_ratio_max, body, mutual_avoidance
        ),
        "dim": 2,
        "dt": dt,
        "control_period": dt,
        "t_max": t_max,
        "goal_tolerance": 0.1,
        "robot": {
            "model": "unicycle",
            "start": list(CH2_START),
            "heading": heading,
            "goal": list(CH2_GOAL),
            "v_max": CH2_V_MAX,
            "u_max": CH2_U_MAX,
            "radius": 0.1,
        },
        "sensing": {"range": 5.0, "velocities": "known", "position_noise": 0.0},
        "obstacles": obstacles,
        "controller": {"name": controller, "params": dict(controller_params or {})},
    }
    return scenario_from_dict(data, source=source)


def _ch2_description(
    seed: int, n: int, speed_ratio: float, turn_ratio: float, body: str, avoid: bool
) -> str:
    what = "non-convex obstacle(s)" if body == "polygon" else "disc obstacle(s)"
    bodies = f"{n} {what} steering around each other" if avoid else f"{n} randomly turning {what}"
    text = (
        f"Random Chapter-2 scene (seed {seed}): {bodies} "
        "near the straight path I->T, all obeying (2.6)-(2.8)."
    )
    if (speed_ratio, turn_ratio, body, avoid) == (
        CH2_SPEED_RATIO,
        CH2_TURN_RATIO,
        "polygon",
        False,
    ):
        return text
    return text + (
        f" Speeds up to {speed_ratio:g} V_max, course turn rates up to {turn_ratio:.3g} U_max."
    )


# ----------------------------------------------------------------------------------- crowd crossing

CROWD_V_MAX = 1.2  # [m/s]
CROWD_U_MAX = 2.0  # [rad/s]
CROWD_ROBOT_RADIUS = 0.3  # [m]
CROWD_T_MAX = 40.0  # [s]
_CROSSING_LENGTH = (8.0, 12.0)  # start-goal distance [m]
_NEAR_CROSSING = 1.5  # [m] from the start-goal segment: a pedestrian "near the crossing"
_MIN_NEAR = 4  # pedestrians near the crossing while the robot could be crossing
_CLEAR_MARGIN = 0.5  # [m] free space between the robot disc and any pedestrian disc at t = 0


def _segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    s = np.clip(((points - a) @ ab) / float(ab @ ab), 0.0, 1.0)
    return np.hypot(*(points - (a + s[:, None] * ab)).T)


def _positive(description: str) -> Any:
    """A finite number > 0, described (the crowd generators' parameters)."""
    return Field(gt=0, allow_inf_nan=False, description=description)


#: the parameters the crowd generators share (``crowd-eth``, ``crowd-hotel``, ``crowd-file``)
_VMax = Annotated[float, _positive("robot V_max [m/s]")]
_UMax = Annotated[float, _positive("robot U_max [rad/s]")]
_Radius = Annotated[float, _positive("pedestrian disc radius [m]")]
_RobotRadius = Annotated[float, _positive("robot disc radius [m]")]
_TMax = Annotated[float, _positive("time limit, also the replayed window [s]")]
_Dt = Annotated[float, _positive("integration and decision step [s]")]
_TStart = Annotated[
    float | None,
    Field(allow_inf_nan=False, description="recording time of t = 0 [s] (drawn when null)"),
]
_Law = Annotated[str, Field(description="default law of the scene")]
_LawParams = Annotated[dict[str, Any] | None, Field(description="its parameters")]


def crowd_crossing_scenario(
    seed: int,
    *,
    dataset: Annotated[Literal["eth", "hotel"], Field(description="ETH recording")] = "eth",
    v_max: _VMax = CROWD_V_MAX,
    u_max: _UMax = CROWD_U_MAX,
    radius: _Radius = 0.3,
    robot_radius: _RobotRadius = CROWD_ROBOT_RADIUS,
    t_max: _TMax = CROWD_T_MAX,
    dt: _Dt = 0.1,
    t_start: _TStart = None,
    controller: _Law = "zhang2019-v1",
    controller_params: _LawParams = None,
) -> Scenario:
    """A robot crossing a walkway of real pedestrians (ETH ``eth`` or ``hotel``), seeded.

    The walkway's main direction is the principal axis of all annotated positions
    (:func:`uvnav.scenarios.pedestrians.walkway_axes`).  Drawn from ``default_rng(seed)``: the
    recording time that becomes t = 0 (unless ``t_start`` is given), the crossing point along the
    walkway (within one standard deviation of the positions along it), the crossing length (8-12 m,
    centred on the walkway's axis) and the side the robot starts on.  A draw is kept when at t = 0
    no pedestrian is within ``robot_radius + radius + 0.5`` m of the start or the goal, and at
    least 4 pedestrians pass within 1.5 m of the start-goal segment during the time the robot
    needs to cross twice at V_max (so the crossing is busy).  Pedestrians do not react to the robot.

    Args:
        seed: the only source of randomness.
        dataset: ``"eth"`` or ``"hotel"``.
        v_max: robot V_max [m/s] (eth pedestrians walk 1.4 m/s on average, hotel 1.0 m/s).
        u_max: robot U_max [rad/s].
        radius: pedestrian disc radius [m].
        robot_radius: robot disc radius [m].
        t_max: time limit, also the replayed window [s].
        dt: integration and decision step [s].
        t_start: recording time of t = 0 [s]; drawn when ``None``.
        controller: default controller of the scene.
        controller_params: its parameters.
    """
    crowd: dict[str, Any] = {"dataset": dataset}
    try:
        found = _crowd_crossing(
            seed, crowd, what=dataset, v_max=v_max, radius=radius, robot_radius=robot_radius,
            t_max=t_max, t_start=t_start,
        )  # fmt: skip
    except RuntimeError as exc:  # no crossing (a t_start outside the recording, say)
        raise ScenarioError(f"crowd-{dataset}:{seed}", "", str(exc)) from None
    start, goal, t0, near, length, horizon = found
    data: dict[str, Any] = {
        "name": f"crowd-{dataset}-seed{seed}",
        "description": (
            f"Crossing the {dataset} walkway (ETH pedestrian recordings, Pellegrini et al. ICCV "
            f"2009; seed {seed}): {near} real pedestrians pass near the {length:.1f} m crossing "
            f"in its first {horizon:.0f} s. Pedestrians do not react to the robot (replayed "
            f"recording). V_max {v_max:g} m/s; pedestrians may be faster, so the thesis's "
            "(2.6)-(2.8) do not hold for all of them."
        ),
        **_crowd_scene_body(
            start, goal, crowd, t0, radius, v_max=v_max, u_max=u_max, robot_radius=robot_radius,
            t_max=t_max, dt=dt, controller=controller, controller_params=controller_params,
        ),
    }  # fmt: skip
    return scenario_from_dict(data, source=f"crowd-{dataset}:{seed}")


def _crowd_scene_body(
    start: np.ndarray,
    goal: np.ndarray,
    crowd: dict[str, Any],
    t0: float,
    radius: float,
    *,
    v_max: float,
    u_max: float,
    robot_radius: float,
    t_max: float,
    dt: float,
    controller: str,
    controller_params: dict[str, Any] | None,
) -> dict[str, Any]:
    return {
        "dim": 2,
        "dt": dt,
        "control_period": dt,
        "t_max": t_max,
        "goal_tolerance": 0.2,
        "robot": {
            "model": "unicycle",
            "start": start.tolist(),
            "goal": goal.tolist(),
            "v_max": v_max,
            "u_max": u_max,
            "radius": robot_radius,
        },
        "sensing": {"range": 5.0, "velocities": "known", "position_noise": 0.0},
        "crowd": {**crowd, "t_start": t0, "radius": radius},
        "controller": {"name": controller, "params": dict(controller_params or {})},
    }


def _crowd_crossing(
    seed: int,
    crowd: dict[str, Any],
    *,
    what: str,
    v_max: float,
    radius: float,
    robot_radius: float,
    t_max: float,
    t_start: float | None,
    start: np.ndarray | None = None,
    goal: np.ndarray | None = None,
    min_near: int = _MIN_NEAR,
) -> tuple[np.ndarray, np.ndarray, float, int, float, float]:
    """Draw a clear, busy crossing of the crowd ``crowd`` (a :class:`CrowdSpec` mapping without
    ``t_start``) from ``default_rng(seed)``: ``(start, goal, t_start, near, length, horizon)``.

    The draws, in order, per try: the recording time of t = 0 (unless ``t_start``), then, unless
    ``start`` and ``goal`` are given, the offset along the walkway axis, the crossing length and
    the side (see :func:`crowd_crossing_scenario`).
    """
    spec = CrowdSpec.model_validate({**crowd, "radius": radius})
    tracks = spec.tracks()
    fixed = start is not None and goal is not None
    if fixed:
        assert start is not None and goal is not None
        start = np.round(np.asarray(start, dtype=float), 3)
        goal = np.round(np.asarray(goal, dtype=float), 3)
        length = float(np.hypot(*(goal - start)))
        if length <= 0.0:
            raise ValueError("start and goal must differ")
    else:
        centre, along, across = walkway_axes(tracks)
        pts = all_positions(tracks)
        spread = float(np.std((pts - centre) @ along))
    t_first = min(float(t.times[0]) for t in tracks.values())
    t_last = max(float(t.times[-1]) for t in tracks.values())
    if t_start is None and t_last - t_max < t_first:
        raise ValueError(
            f"the recording lasts {t_last - t_first:.1f} s, shorter than t_max = {t_max:g} s"
        )
    clear = robot_radius + radius + _CLEAR_MARGIN
    rng = np.random.default_rng(seed)
    for _ in range(_MAX_TRIES):
        t0 = (
            round(float(rng.uniform(t_first, t_last - t_max)), 1)
            if t_start is None
            else float(t_start)
        )
        if not fixed:
            offset = float(rng.uniform(-spread, spread))
            length = float(rng.uniform(*_CROSSING_LENGTH))
            side = 1.0 if rng.random() < 0.5 else -1.0
            mid = centre + offset * along
            start = np.round(mid - side * 0.5 * length * across, 3)
            goal = np.round(mid + side * 0.5 * length * across, 3)
        assert start is not None and goal is not None
        pieces = episode_tracks(
            tracks, t_start=t0, duration=t_max, region=spec.region, at_rest=spec.at_rest
        )
        now = [p for p in pieces if p.times[0] <= 1e-9 <= p.times[-1] + 1e-9]
        at0 = np.array(
            [
                [
                    np.interp(0.0, p.times, p.positions[:, 0]),
                    np.interp(0.0, p.times, p.positions[:, 1]),
                ]
                for p in now
            ]
        ).reshape(-1, 2)
        if len(at0) and (
            np.min(np.hypot(*(at0 - start).T)) < clear or np.min(np.hypot(*(at0 - goal).T)) < clear
        ):
            continue
        horizon = min(t_max, 2.0 * length / v_max)
        near = 0
        for p in pieces:
            inside = (p.times >= 0.0) & (p.times <= horizon)
            if inside.any() and _segment_distance(p.positions[inside], start, goal).min() < (
                _NEAR_CROSSING
            ):
                near += 1
        if near < min_near:
            continue
        return start, goal, t0, near, length, horizon
    raise RuntimeError(f"no busy, clear crossing found in {what} (seed {seed})")


CROWD_FILE_FORMATS = FORMATS


@typed_generator("crowd-file")
def crowd_file_scenario(
    seed: int,
    *,
    path: Annotated[str | None, Field(description="trajectory file (required)")] = None,
    format: Annotated[
        Literal["obsmat", "xy4", "trajnet"], Field(description="its format")
    ] = "obsmat",
    frame_rate: Annotated[
        float | None,
        Field(gt=0, allow_inf_nan=False, description="frames/s (inferred when null)"),
    ] = None,
    scale: Annotated[float, _positive("positions scale * p + offset")] = 1.0,
    offset: Annotated[
        tuple[float, float], Field(description="positions scale * p + offset [m]")
    ] = (0.0, 0.0),
    start: Annotated[
        tuple[float, float] | None, Field(description="robot start [m] (with goal)")
    ] = None,
    goal: Annotated[
        tuple[float, float] | None, Field(description="robot goal [m] (with start)")
    ] = None,
    stitch: Annotated[bool, Field(description="join a track that ends where one starts")] = True,
    at_rest: Annotated[bool, Field(description="people wait at their first position")] = False,
    region: Annotated[
        tuple[float, float, float, float] | None,
        Field(description="only people inside x0, y0, x1, y1 [m]"),
    ] = None,
    min_near: Annotated[
        int, Field(ge=0, description="people near the line while crossing (0: any)")
    ] = _MIN_NEAR,
    v_max: _VMax = CROWD_V_MAX,
    u_max: _UMax = CROWD_U_MAX,
    radius: _Radius = 0.3,
    robot_radius: _RobotRadius = CROWD_ROBOT_RADIUS,
    t_max: _TMax = CROWD_T_MAX,
    dt: _Dt = 0.1,
    t_start: _TStart = None,
    controller: _Law = "zhang2019-v1",
    controller_params: _LawParams = None,
) -> Scenario:
    """A robot crossing the crowd of any trajectory file (``crowd-file:<seed>``), seeded.

    The file (``path``, relative to the current folder; ``.gz`` read transparently) is read as
    ``format`` ``obsmat`` (ETH), ``xy4`` (``frame id x y``, ``?`` for hidden positions) or
    ``trajnet`` (TrajNet++ ndjson), at ``frame_rate`` frames/s (inferred from a 0.4 s annotation
    period when omitted), positions ``scale * p + offset`` [m].  Hidden positions are skipped with
    a warning; a malformed file is one :class:`ScenarioError` line naming the file and the line.
    With ``stitch`` (default on) a track that ends where another starts, at most one annotation
    step later and within 1 m, is one person (:func:`~uvnav.scenarios.pedestrians.stitch_tracks`);
    with ``at_rest`` people whose track starts after t = 0 wait at rest at their first position.

    The crossing line:

    * default: across the walkway axis estimated from the tracks (the principal axis of every
      annotated position), exactly as :func:`crowd_crossing_scenario` draws it for the ETH
      recordings (crossing point, 8-12 m length and side drawn from the seed);
    * ``start`` and ``goal`` [m] given: that line, only the recording time of t = 0 is drawn.

    Either way a draw is kept when nobody is within ``robot_radius + radius + 0.5`` m of the start
    or the goal at t = 0 and at least ``min_near`` people pass within 1.5 m of the line while the
    robot could be crossing (0 accepts any time); ``t_start`` fixes the recording time of t = 0.
    The other arguments are those of :func:`crowd_crossing_scenario`.

    Raises:
        ScenarioError: no ``path``, an unreadable or malformed file, or bad parameters.
    """
    source = f"crowd-file:{seed}"
    if path is None:
        raise ScenarioError(
            source,
            "params",
            "crowd-file needs params: path (and format: obsmat | xy4 | trajnet); give them in a "
            "campaign entry (generator: crowd-file, params: {path: ...}) or write a scene with "
            "a crowd: section",
        )
    if (start is None) != (goal is None):
        raise ScenarioError(source, "params", "give both start and goal, or neither")
    file = Path(str(path)).expanduser()
    if not file.is_file():
        raise ScenarioError(source, "params", f"path: no such file {str(path)!r}")
    crowd: dict[str, Any] = {
        "dataset": str(file.resolve()),
        "format": format,
        "frame_rate": frame_rate,
        "scale": scale,
        "offset": list(offset),
        "stitch": bool(stitch),
        "at_rest": bool(at_rest),
        "region": None if region is None else list(region),
    }
    crowd = {k: v for k, v in crowd.items() if v is not None}
    try:  # the file's own problems first: one line naming it and the line
        load_tracks(crowd["dataset"], format, frame_rate=frame_rate)
    except ScenarioError as exc:
        raise ScenarioError(source, "params", f"path: {exc}") from None
    try:
        found = _crowd_crossing(
            seed, crowd, what=file.name, v_max=v_max, radius=radius, robot_radius=robot_radius,
            t_max=t_max, t_start=t_start,
            start=None if start is None else np.asarray(start, dtype=float),
            goal=None if goal is None else np.asarray(goal, dtype=float),
            min_near=int(min_near),
        )  # fmt: skip
    except ValidationError as exc:  # scale, offset, frame_rate, region ...
        err = from_validation_error(exc, source)
        raise ScenarioError(source, "params", f"{err.path}: {err.problem}") from None
    except RuntimeError as exc:
        raise ScenarioError(source, "", str(exc)) from None
    start_, goal_, t0, near, length, horizon = found
    data: dict[str, Any] = {
        "name": f"crowd-file-{file.stem.split('.')[0]}-seed{seed}",
        "description": (
            f"Crossing the crowd of {file.name} (seed {seed}): {near} recorded pedestrians pass "
            f"near the {length:.1f} m crossing in its first {horizon:.0f} s. Pedestrians do not "
            f"react to the robot (replayed recording). V_max {v_max:g} m/s; pedestrians may be "
            "faster, so the thesis's (2.6)-(2.8) do not hold for all of them."
        ),
        **_crowd_scene_body(
            start_, goal_, crowd, t0, radius, v_max=v_max, u_max=u_max,
            robot_radius=robot_radius, t_max=t_max, dt=dt, controller=controller,
            controller_params=controller_params,
        ),
    }  # fmt: skip
    return scenario_from_dict(data, source=source)


#: The generator a campaign job draws its scene from when it names none.
DEFAULT_GENERATOR = "random-ch2"

#: Seeded scenario generators by name: ``GENERATORS[name](seed, **params) -> Scenario``.
#: ``load_scenario("<name>:<seed>")`` and campaign files refer to them by these names.
GENERATORS: dict[str, Callable[..., Any]] = {
    "random-ch2": random_ch2_scenario,
    "random-ch2-edge": generator_variant("random-ch2-edge", random_ch2_scenario, **CH2_EDGE),
    "crowd-eth": typed_generator("crowd-eth")(partial(crowd_crossing_scenario, dataset="eth")),
    "crowd-hotel": typed_generator("crowd-hotel")(
        partial(crowd_crossing_scenario, dataset="hotel")
    ),
    "crowd-file": crowd_file_scenario,
    "random-ch3": random_ch3_scenario,
    "random-ch3-periodic": generator_variant(
        "random-ch3-periodic", random_ch3_scenario, motion="periodic"
    ),
    "crowdnav-circle": crowdnav_circle,
    "crowdnav-square": crowdnav_square,
    "crowd-dynamic": crowd_dynamic_scenario,
}


def generate(name: str, seed: int, **params: Any) -> Scenario:
    """Scenario number ``seed`` of the generator ``name`` (a key of :data:`GENERATORS`)."""
    if name not in GENERATORS:
        raise KeyError(
            f"unknown scenario generator {name!r}; known: {', '.join(sorted(GENERATORS))}"
        )
    return GENERATORS[name](seed, **params)
