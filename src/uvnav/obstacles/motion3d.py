"""Moving, rotating 3D obstacles and their motion models.

Thesis Chapter 3 §3.2 (Y. Zhang, ICCAR 2020): obstacle i moves with velocity v_i(t) = V_i(t) a_i(t)
and rotates about its mass centre with rotation vector u_i(t), subject to (3.9)
0 < ||v_i|| < ||v_R|| < V_max and (3.10) ||u_i|| < ||u_R|| < U_max.  §3.3.1 assumes the motion
"changes slowly" so that an AR model predicts it; the models here are:

* :class:`ConstantMotion3D` — fixed v_i, u_i;
* :class:`ARMotion3D` — v_i and u_i are AR(p) processes sampled every ``period`` T_s [s] (1 s in
  the thesis) around a mean, held constant within a period, with their norms kept in the bounds
  of (3.9)-(3.10) (a draw outside is scaled back to the bound): the "slowly varying" motion the
  AR predictor of :mod:`uvnav.prediction.autoregressive` is built for;
* :class:`PeriodicMotion3D` — weaving or circling about a mean velocity,
  sampled every ``period`` T_s and held within it like the AR motion, its norm kept below the
  bound of (3.9): the oscillation o_k = v_k - v_mean follows o_k = 2 r cos(w T_s) o_{k-1} -
  r^2 o_{k-2} + sigma e_k — a sinusoid for r = 1, sigma = 0, else an oscillator driven by noise
  (an AR(2) process with complex roots) — the case where (3.13)-(3.14) should beat constant
  velocity;
* :class:`Waypoints3D` — a scripted path through points at a fixed speed, with a fixed spin.

Integration of one step ``dt`` with (v, u) held is exact: ``c += v dt``,
``R = exp([u]x dt) R``.  Randomness only from the ``numpy.random.Generator`` a model is built with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.frames3d import rotation_from_vector
from uvnav.obstacles.bodies3d import Body3D


@dataclass
class ObstacleState3D:
    """Pose and rates of a 3D obstacle.

    Attributes:
        centre: mass centre [m], (3,).
        rotation: body-to-world rotation matrix (3, 3).
        velocity: v_i [m/s], (3,), held over the current step.
        rotation_rate: u_i [rad/s], (3,), world frame, held over the current step.
    """

    centre: FloatArray
    rotation: FloatArray = field(default_factory=lambda: np.eye(3))
    velocity: FloatArray = field(default_factory=lambda: np.zeros(3))
    rotation_rate: FloatArray = field(default_factory=lambda: np.zeros(3))


class MotionModel3D(Protocol):
    """Sets the obstacle's (v_i, u_i) for the step starting at ``t`` [s]."""

    def rates(self, t: float, state: ObstacleState3D) -> tuple[FloatArray, FloatArray]: ...


def _clip_norm(x: FloatArray, lo: float, hi: float) -> FloatArray:
    n = float(np.linalg.norm(x))
    if n > hi:
        return x * (hi / n)
    if n < lo:
        if n < 1e-12:
            return np.array([lo, 0.0, 0.0])
        return x * (lo / n)
    return x


@dataclass
class ConstantMotion3D:
    """Constant velocity ``velocity`` [m/s] and rotation ``rotation_rate`` [rad/s] (world frame)."""

    velocity: FloatArray
    rotation_rate: FloatArray = field(default_factory=lambda: np.zeros(3))

    def rates(self, t: float, state: ObstacleState3D) -> tuple[FloatArray, FloatArray]:
        return np.asarray(self.velocity, float), np.asarray(self.rotation_rate, float)


@dataclass
class ARMotion3D:
    """Slowly varying random motion: per component, an AR(p) process sampled every ``period``.

    ``x_k = mean + sum_j phi_j (x_{k-j} - mean) + sigma e_k`` (e_k standard normal), for the
    velocity (``v_*``) and the rotation vector (``u_*``); each new sample is scaled into
    ``[v_min, v_max]`` / ``[0, u_max]`` by norm.

    Attributes:
        rng: the generator of the noise.
        v_mean: mean velocity [m/s], (3,).
        phi: AR coefficients (p,) shared by both processes (stationary choices only).
        v_sigma: noise std of the velocity [m/s].
        v_min, v_max: bounds on ||v_i|| [m/s] ((3.9) with v_max < the robot's speed).
        u_mean: mean rotation vector [rad/s], (3,).
        u_sigma: noise std of the rotation vector [rad/s].
        u_max: bound on ||u_i|| [rad/s] ((3.10)).
        period: sampling period T_s [s] (thesis: 1 s).
    """

    rng: np.random.Generator
    v_mean: FloatArray
    phi: FloatArray = field(default_factory=lambda: np.array([0.6, 0.2]))
    v_sigma: float = 0.05
    v_min: float = 0.05
    v_max: float = 0.5
    u_mean: FloatArray = field(default_factory=lambda: np.zeros(3))
    u_sigma: float = 0.02
    u_max: float = 0.3
    period: float = 1.0
    _k: int = field(default=-1, init=False)
    _v_hist: list[FloatArray] = field(default_factory=list, init=False)
    _u_hist: list[FloatArray] = field(default_factory=list, init=False)

    def _next(self, hist: list[FloatArray], mean: FloatArray, sigma: float) -> FloatArray:
        x = mean.copy()
        for j, ph in enumerate(np.asarray(self.phi, float)):
            prev = hist[-1 - j] if j < len(hist) else mean
            x = x + ph * (prev - mean)
        return np.asarray(x + sigma * self.rng.standard_normal(3))

    def rates(self, t: float, state: ObstacleState3D) -> tuple[FloatArray, FloatArray]:
        k = math.floor(t / self.period + 1e-9)
        while self._k < k:
            self._k += 1
            vm = np.asarray(self.v_mean, float)
            um = np.asarray(self.u_mean, float)
            if not self._v_hist:
                v = _clip_norm(vm.copy(), self.v_min, self.v_max)
                u = _clip_norm(um.copy(), 0.0, self.u_max)
            else:
                v = _clip_norm(self._next(self._v_hist, vm, self.v_sigma), self.v_min, self.v_max)
                u = _clip_norm(self._next(self._u_hist, um, self.u_sigma), 0.0, self.u_max)
            self._v_hist.append(v)
            self._u_hist.append(u)
            if len(self._v_hist) > 16:
                del self._v_hist[0], self._u_hist[0]
        return self._v_hist[-1], self._u_hist[-1]


@dataclass
class PeriodicMotion3D:
    """Weaving / circling motion about a mean velocity, sampled every ``period`` T_s.

    The sample of period k (from ``t_k = k T_s``) is ``v_k = v_mean + o_k`` with the oscillation

        o_k = 2 r cos(w T_s) o_{k-1} - r^2 o_{k-2} + v_sigma e_k,    w = 2 pi / osc_period,

    e_k standard normal (3,), started on ``o(t) = amp_cos cos(w t + phase) + amp_sin sin(w t +
    phase)`` at t = 0 and t = -T_s.  With ``damping`` r = 1 and ``v_sigma`` = 0 this is that
    sinusoid exactly (its samples obey the recursion); r < 1 and v_sigma > 0 make it an
    oscillator driven by noise, an AR(2) process with complex roots r exp(+-i w T_s).  A sample is
    scaled back to ``v_max`` by norm when above it (3.9) and held within its period, as
    :class:`ARMotion3D` holds its samples; the rotation ``rotation_rate`` is constant.  With
    ``v_sigma = 0`` no random draws are made.

    Attributes:
        v_mean: mean velocity [m/s], (3,).
        amp_cos, amp_sin: initial oscillation amplitudes [m/s], (3,) each; one of them zero gives
            a weave along a line, two orthogonal ones of equal norm a circle (a helix about
            ``v_mean``).
        osc_period: period of the oscillation [s].
        phase: phase at t = 0 [rad].
        v_max: bound on ||v_i|| [m/s] ((3.9)).
        rotation_rate: u_i [rad/s], (3,), world frame.
        period: sampling period T_s [s].
        damping: r in (0, 1], the modulus of the recursion's roots.
        v_sigma: std of the innovation e_k's scale [m/s] (needs ``rng`` when > 0).
        rng: the generator of the innovations.
    """

    v_mean: FloatArray
    amp_cos: FloatArray
    amp_sin: FloatArray
    osc_period: float
    phase: float = 0.0
    v_max: float = 0.5
    rotation_rate: FloatArray = field(default_factory=lambda: np.zeros(3))
    period: float = 1.0
    damping: float = 1.0
    v_sigma: float = 0.0
    rng: np.random.Generator | None = None
    _k: int = field(default=-1, init=False)
    _osc: tuple[FloatArray, FloatArray] = field(
        default_factory=lambda: (np.zeros(3), np.zeros(3)), init=False
    )
    _v: FloatArray = field(default_factory=lambda: np.zeros(3), init=False)

    def __post_init__(self) -> None:
        if self.v_sigma > 0 and self.rng is None:
            raise ValueError("v_sigma > 0 needs an rng")
        if not 0.0 < self.damping <= 1.0:
            raise ValueError(f"damping must be in (0, 1] (got {self.damping!r})")

    def _sinusoid(self, t: float) -> FloatArray:
        a = 2.0 * math.pi / self.osc_period * t + self.phase
        return np.asarray(
            math.cos(a) * np.asarray(self.amp_cos, float)
            + math.sin(a) * np.asarray(self.amp_sin, float)
        )

    def _next(self) -> FloatArray:
        """The oscillation o_k of the next period (advances the recursion)."""
        self._k += 1
        if self._k == 0:
            o = self._sinusoid(0.0)
            self._osc = (o, self._sinusoid(-self.period))
            return o
        prev, prev2 = self._osc
        c = math.cos(2.0 * math.pi / self.osc_period * self.period)
        r = self.damping
        o = 2.0 * r * c * prev - r * r * prev2
        if self.v_sigma > 0 and self.rng is not None:
            o = o + self.v_sigma * self.rng.standard_normal(3)
        self._osc = (o, prev)
        return np.asarray(o)

    def rates(self, t: float, state: ObstacleState3D) -> tuple[FloatArray, FloatArray]:
        k = math.floor(t / self.period + 1e-9)
        while self._k < k:  # one sample per period, in order, whatever the step
            o = self._next()
            self._v = _clip_norm(np.asarray(self.v_mean, float) + o, 0.0, self.v_max)
        return self._v, np.asarray(self.rotation_rate, float)


@dataclass
class Waypoints3D:
    """Scripted path: straight at ``speed`` [m/s] through ``points`` (k, 3) [m], then back along
    them when ``loop`` (ping-pong), else stop at the last; spins with ``rotation_rate``."""

    points: FloatArray
    speed: float
    rotation_rate: FloatArray = field(default_factory=lambda: np.zeros(3))
    loop: bool = True
    _i: int = field(default=0, init=False)
    _step: int = field(default=1, init=False)

    def rates(self, t: float, state: ObstacleState3D) -> tuple[FloatArray, FloatArray]:
        pts = np.asarray(self.points, float)
        u = np.asarray(self.rotation_rate, float)
        for _ in range(2 * len(pts) + 1):
            gap = pts[self._i] - state.centre
            dist = float(np.linalg.norm(gap))
            if dist > 1e-9:
                return gap / dist * self.speed, u
            nxt = self._i + self._step
            if not 0 <= nxt < len(pts):
                if not self.loop or len(pts) < 2:
                    return np.zeros(3), u
                self._step = -self._step
                nxt = self._i + self._step
            self._i = nxt
        return np.zeros(3), u


@dataclass
class Obstacle3D:
    """A body, its motion model and its current state."""

    body: Body3D
    motion: MotionModel3D
    state: ObstacleState3D
    #: exp([u]x dt) of the last step and its key (u's bytes, dt): the rates are held for whole
    #: sampling periods, so the same rotation is reused bit for bit while they do not change
    _step_rotation: tuple[bytes, float, FloatArray | None] | None = field(
        default=None, init=False, repr=False, compare=False
    )

    def step(self, t: float, dt: float) -> None:
        """Advance by ``dt`` [s] from time ``t`` [s] with the rates the model gives for the step
        (stored in the state as the rates held over it)."""
        v, u = self.motion.rates(t, self.state)
        self.state.velocity = v
        self.state.rotation_rate = u
        self.state.centre = self.state.centre + v * dt
        key = u.tobytes()
        cached = self._step_rotation
        if cached is None or cached[0] != key or cached[1] != dt:
            # None: no rotation (u = 0)
            cached = (key, dt, rotation_from_vector(u * dt) if float(u @ u) > 0.0 else None)
            self._step_rotation = cached
        if cached[2] is not None:
            self.state.rotation = cached[2] @ self.state.rotation

    def to_body(self, point: FloatArray) -> FloatArray:
        """World point -> body frame."""
        return np.asarray(self.state.rotation.T @ (np.asarray(point, float) - self.state.centre))

    def to_world(self, points: FloatArray) -> FloatArray:
        """Body-frame points (n, 3) -> world."""
        return np.asarray(points) @ self.state.rotation.T + self.state.centre

    def nearest(self, point: FloatArray) -> tuple[FloatArray, float]:
        """Nearest surface point (world) to ``point`` and the signed distance [m] (3.8)."""
        return self.body.nearest_world(point, self.state.centre, self.state.rotation)

    def ray_cast(self, origins: FloatArray, directions: FloatArray) -> FloatArray:
        """Distance [m] along each world ray (unit directions) to the body (inf: miss)."""
        o = (np.atleast_2d(origins) - self.state.centre) @ self.state.rotation
        d = np.atleast_2d(directions) @ self.state.rotation
        return self.body.ray_body(o, d)

    def world_outline(self) -> FloatArray:
        """The body's spanning points in the world frame (n, 3) [m]."""
        return self.to_world(self.body.outline_points())
