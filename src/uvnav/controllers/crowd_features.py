"""A crowd observation for learned laws: the robot's own state and a masked set of its nearest
humans, in the robot's goal frame, made from nothing but its :class:`~uvnav.sensors.Observation`.

The frame (CrowdNav's "rotated" state, Chen et al., ICRA 2019): origin at the robot's centre,
x axis toward the goal (the world x axis when the robot is on its goal).  In that frame:

* robot (:data:`ROBOT_DIM` numbers): goal distance / :data:`POS_SCALE` [m / m] (clipped to
  :data:`GOAL_CLIP`), the robot's velocity (vx, vy) / V_max;
* each of ``k`` human slots (:data:`HUMAN_DIM` numbers, then a mask): centre (x, y) /
  :data:`POS_SCALE`, velocity (vx, vy) / V_max, radius [m], gap (centre distance minus both
  radii) / :data:`POS_SCALE`, clipped to [-1, :data:`GAP_CLIP`]; then 1 for a seen human, 0 for
  an empty slot (all zeros).

The humans are the observation's disc readings (the laws' sensing range decides which are seen;
polygons are not humans and are left out), the ``k`` with the smallest gap, nearest first.  A
robot velocity is ``speed [cos heading, sin heading]`` (the holonomic robot's observation).
The flat vector is ``robot + k x (human + mask)`` float32 (:func:`crowd_vector`).
"""

from __future__ import annotations

import math

import numpy as np

from uvnav.sensors.observation import Observation

#: numbers of the robot's part
ROBOT_DIM = 3
#: numbers of one human's slot before its mask
HUMAN_DIM = 6
#: lengths [m] mapped to 1
POS_SCALE = 4.0
#: largest scaled goal distance
GOAL_CLIP = 3.0
#: largest scaled gap
GAP_CLIP = 2.0


def vector_size(k: int) -> int:
    """Length of the flat vector with ``k`` human slots."""
    return ROBOT_DIM + k * (HUMAN_DIM + 1)


def goal_frame(obs: Observation) -> tuple[float, float, float]:
    """``(cos a, sin a, distance)``: the goal frame's x axis at angle ``a`` [rad] in the world
    and the goal distance [m] (``a`` = 0 on the goal or for a non-finite observation)."""
    gx = float(obs.goal[0]) - float(obs.pose[0])
    gy = float(obs.goal[1]) - float(obs.pose[1])
    d = math.hypot(gx, gy)
    if not math.isfinite(d) or d < 1e-9:
        return 1.0, 0.0, d if math.isfinite(d) else 0.0
    return gx / d, gy / d, d


def crowd_features(
    obs: Observation, k: int, v_max: float, radius: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(robot (ROBOT_DIM,), humans (k, HUMAN_DIM), mask (k,))`` of ``obs`` (module docstring)
    for a robot of ``v_max`` [m/s] and ``radius`` [m]; float64, finite."""
    c, s, d = goal_frame(obs)
    speed, heading = float(obs.speed), float(obs.heading)
    if not (math.isfinite(speed) and math.isfinite(heading)):
        speed, heading = 0.0, 0.0
    vx, vy = speed * math.cos(heading), speed * math.sin(heading)
    robot = np.array(
        [min(d / POS_SCALE, GOAL_CLIP), (c * vx + s * vy) / v_max, (-s * vx + c * vy) / v_max]
    )
    humans = np.zeros((k, HUMAN_DIM))
    mask = np.zeros(k)
    px, py = float(obs.pose[0]), float(obs.pose[1])
    rows: list[tuple[float, int, list[float]]] = []
    for i, r in enumerate(obs.obstacles):
        if not r.is_disc:
            continue
        dx, dy = float(r.centre[0]) - px, float(r.centre[1]) - py
        hvx, hvy = float(r.velocity[0]), float(r.velocity[1])
        row = [dx, dy, hvx, hvy, float(r.radius)]
        if not all(math.isfinite(v) for v in row):
            continue
        gap = math.hypot(dx, dy) - float(r.radius) - radius
        rows.append((gap, i, [*row, gap]))
    rows.sort(key=lambda t: (t[0], t[1]))
    for j, (gap, _, (dx, dy, hvx, hvy, hr, _g)) in enumerate(rows[:k]):
        humans[j] = (
            (c * dx + s * dy) / POS_SCALE,
            (-s * dx + c * dy) / POS_SCALE,
            (c * hvx + s * hvy) / v_max,
            (-s * hvx + c * hvy) / v_max,
            hr,
            min(max(gap / POS_SCALE, -1.0), GAP_CLIP),
        )
        mask[j] = 1.0
    return robot, humans, mask


def crowd_vector(obs: Observation, k: int, v_max: float, radius: float) -> np.ndarray:
    """The flat float32 vector ``robot + k x (human + mask)`` of :func:`crowd_features`."""
    robot, humans, mask = crowd_features(obs, k, v_max, radius)
    return np.concatenate([robot, np.hstack([humans, mask[:, None]]).ravel()]).astype(np.float32)


def split_vector(x: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(robot (..., ROBOT_DIM), humans (..., k, HUMAN_DIM), mask (..., k))`` of flat vectors
    ``x`` (..., :func:`vector_size` (k)): :func:`crowd_vector`'s inverse."""
    robot = x[..., :ROBOT_DIM]
    slots = x[..., ROBOT_DIM:].reshape(*x.shape[:-1], k, HUMAN_DIM + 1)
    return robot, slots[..., :HUMAN_DIM], slots[..., HUMAN_DIM]


def action_velocity(action: np.ndarray, obs: Observation, v_max: float) -> tuple[float, float]:
    """The world-frame velocity [m/s] of an action in [-1, 1]^2 (clipped): ``V_max a`` in the
    goal frame, scaled onto the disc of radius V_max when longer."""
    a0 = min(max(float(action[0]), -1.0), 1.0)
    a1 = min(max(float(action[1]), -1.0), 1.0)
    if not (math.isfinite(a0) and math.isfinite(a1)):
        return 0.0, 0.0
    n = math.hypot(a0, a1)
    if n > 1.0:
        a0, a1 = a0 / n, a1 / n
    c, s, _ = goal_frame(obs)
    return v_max * (c * a0 - s * a1), v_max * (s * a0 + c * a1)
