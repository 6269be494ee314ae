"""Seeded generator of random 3D scenes of the kind of thesis Chapter 3 (``random-ch3:<seed>``).

The robot (V_max = 1 m/s, U_max = 1 rad/s, radius 0.1 m) flies from S = [0, 0, 5] to an end point E
20-26 m away in a random horizontal direction and 0-6 m higher or lower.  ``n_obstacles`` (2-4 by
default) non-convex star-shaped bodies (base radius 0.8-1.5 m, 2-4 bumps and dents, the dents'
relative depths summing to at most 0.5) are placed so
that, moving with their *mean* velocity, they would sit near the straight path S-E when the robot
gets there (lateral and vertical offsets within +-1.2 m): they are in the way.  Their motion is
:class:`~uvnav.obstacles.motion3d.ARMotion3D` — slowly varying AR(2) velocity and rotation — with
||v_i|| <= 0.5 V_max and ||u_i|| <= 0.3 U_max, so (3.9)-(3.10) hold with room to spare.  Bodies
start at least 3 m apart surface to surface (the thesis excludes narrow gaps, Fig. 3.1(c)) and
3 m from S and E.  Everything is drawn from ``np.random.default_rng(seed)``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from uvnav.scenarios.schema3d import Scenario3D, scenario3d_from_dict

V_MAX = 1.0
U_MAX = 1.0


def _star(rng: np.random.Generator) -> tuple[dict[str, Any], float]:
    r0 = float(rng.uniform(0.8, 1.5))
    bumps = []
    bound = 1.0
    dents = 0.0
    for _ in range(int(rng.integers(2, 5))):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        h = float(rng.uniform(0.2, 0.6)) * (1 if rng.random() < 0.6 else -0.5)
        if h < 0:
            if dents + h < -0.5:  # keep the body solid: dents sum to at most -0.5
                h = -h
            else:
                dents += h
        bumps.append(
            {"direction": [float(x) for x in d], "height": round(h, 3),
             "sharpness": round(float(rng.uniform(3.0, 6.0)), 3)}
        )  # fmt: skip
        bound += max(h, 0.0)
    return {"star": {"radius": round(r0, 3), "bumps": bumps, "subdivisions": 2}}, r0 * bound


def random_ch3_scenario(
    seed: int,
    *,
    n_obstacles: int | None = None,
    velocities: str = "estimated",
    t_max: float = 90.0,
) -> Scenario3D:
    """Random 3D scene number ``seed`` (see the module docstring).

    Args:
        seed: the scene's seed (the same seed gives the same scene).
        n_obstacles: number of obstacles (default: 2-4 drawn from the seed).
        velocities: ``"estimated"`` (finite differences, AR-predicted by the law) or ``"known"``.
        t_max: time limit [s].
    """
    rng = np.random.default_rng(seed)
    n = int(n_obstacles) if n_obstacles is not None else int(rng.integers(2, 5))
    start = np.array([0.0, 0.0, 5.0])
    heading = rng.uniform(0, 2 * math.pi)
    length = float(rng.uniform(20.0, 26.0))
    climb = float(rng.uniform(-6.0, 6.0))
    horiz = math.sqrt(max(length * length - climb * climb, 1.0))
    goal = start + np.array([horiz * math.cos(heading), horiz * math.sin(heading), climb])
    axis = (goal - start) / np.linalg.norm(goal - start)
    side = np.cross(axis, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    up = np.cross(side, axis)
    placed: list[tuple[np.ndarray, float]] = []
    obstacles: list[dict[str, Any]] = []
    tries = 0
    while len(obstacles) < n and tries < 400:
        tries += 1
        body, bound = _star(rng)
        frac = float(rng.uniform(0.25, 0.8))
        speed = float(rng.uniform(0.1, 0.4))
        vdir = rng.normal(size=3)
        vdir[2] *= 0.3
        vdir /= np.linalg.norm(vdir)
        v_mean = speed * vdir
        u_mean = rng.normal(size=3)
        u_mean *= float(rng.uniform(0.0, 0.2)) / np.linalg.norm(u_mean)
        meet = start + frac * (goal - start)
        meet = meet + side * rng.uniform(-1.2, 1.2) + up * rng.uniform(-1.2, 1.2)
        t_meet = frac * length / V_MAX
        centre = meet - v_mean * t_meet
        if np.linalg.norm(centre - start) < bound + 3.0 or np.linalg.norm(centre - goal) < (
            bound + 3.0
        ):
            continue
        if any(np.linalg.norm(centre - c) < bound + b + 3.0 for c, b in placed):
            continue
        placed.append((centre, bound))
        obstacles.append(
            {
                "body": body,
                "start": {
                    "position": [round(float(x), 4) for x in centre],
                    "rotation": [round(float(x), 4) for x in rng.uniform(-math.pi, math.pi, 3)],
                },
                "motion": {
                    "type": "ar",
                    "v_mean": [round(float(x), 4) for x in v_mean],
                    "phi": [0.6, 0.25],
                    "v_sigma": 0.04,
                    "v_min": 0.02,
                    "v_max": 0.5 * V_MAX,
                    "u_mean": [round(float(x), 4) for x in u_mean],
                    "u_sigma": 0.02,
                    "u_max": 0.3 * U_MAX,
                    "period": 1.0,
                },
            }
        )
    data = {
        "name": f"random-ch3:{seed}",
        "description": "random 3D scene of thesis Ch. 3 (moving, rotating non-convex bodies)",
        "dim": 3,
        "dt": 0.05,
        "control_period": 0.1,
        "t_max": t_max,
        "goal_tolerance": 0.3,
        "robot": {
            "start": [float(x) for x in start],
            "goal": [round(float(x), 4) for x in goal],
            "v_max": V_MAX,
            "u_max": U_MAX,
            "radius": 0.1,
        },
        "sensing": {"range": 8.0, "velocities": velocities},
        "obstacles": obstacles,
        "controller": {"name": "zhang2020-3d-v1"},
    }
    return scenario3d_from_dict(data, f"random-ch3:{seed}")
