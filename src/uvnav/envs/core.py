"""What the Gymnasium and PettingZoo environments add to the loop's worlds (no gymnasium import).

The envs step the worlds of the one step loop (:mod:`uvnav.core`): ``uvnav/Nav2D-v0`` a
:class:`uvnav.sim.episode.World2D`, the multi-robot ParallelEnv a
:class:`uvnav.sim.multi.MultiUnicycleWorld`.  :class:`EnvWorld` steps such a world one *decision*
at a time — the agents' commands are applied at a decision time, then the world advances (every
``dt``, integration, obstacles and collision checks are the world's own) until the next decision
or the end — so an env episode is, bit for bit, the simulator's episode
(:func:`uvnav.sim.run_episode`, :func:`uvnav.sim.run.run_episode`) driven by the same commands.
What is genuinely the env's is here: the observation vector, the action map, the reward and the
frames.

Observation vector of a robot (float32, documented in :data:`OBS_DOC`):

====================  ==========================================================  =========
index                 what                                                         range
====================  ==========================================================  =========
0                     distance to goal / ``goal_scale``, clipped                   [0, 1]
1, 2                  cos, sin of the goal bearing in the robot frame              [-1, 1]
3                     current speed / V_max                                        [0, 1]
4 ..                  lidar ranges / max_range (``n_rays`` beams, robot frame,     [0, 1]
                      first beam straight behind, counter-clockwise)
====================  ==========================================================  =========

Action (float32, in [-1, 1]^2): for the unicycle ``v = (a0 + 1) / 2 * V_max``, ``u = a1 *
U_max``; for another planar vehicle each component mapped linearly onto its command box
(:meth:`~uvnav.dynamics.vehicles.Vehicle2D.bounds`) — inside the limits by construction, so no
limit is ever violated.  With ``raw_commands=True`` the action is instead the command itself
(the unicycle's ``(v [m/s], u [rad/s])``, a vehicle's :meth:`~uvnav.dynamics.vehicles.Vehicle2D.
pair`) as float64, handed to the world as a uvnav law's command is (saturated and counted in
``limit_violations`` when outside the limits): the normalised float32 map cannot carry a law's
command exactly (a law's ``u`` rounded to float32 moves the trajectory by ~1e-9 m per step), the
raw one can.

Reward per decision (weights in :class:`RewardConfig`): ``progress`` x (decrease of the distance
to the goal [m]) ``- time`` ``- clearance`` x max(0, ``clearance_margin`` - clearance [m]) ``+
success`` on arrival ``- collision`` on a collision, where the clearance is the smallest gap of
the robot's disc to an obstacle or another robot over the decision's integration steps
(``max_range`` when nothing is within the robot's reach).
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.obstacles.obstacle import ObstacleField
from uvnav.sensors.exact import beam_offsets, lidar_scan
from uvnav.sensors.observation import Observation
from uvnav.sim.bodies2d import PackedBodies
from uvnav.sim.episode import World2D
from uvnav.sim.multi import MultiUnicycleWorld
from uvnav.validation import MAX_COORDINATE, clip, one_line

OBS_DOC = (
    "[goal distance / goal_scale, cos(goal bearing), sin(goal bearing), speed / v_max, "
    "lidar ranges / max_range x n_rays]"
)

#: The float dtypes an action array is read from as it is (exactly, as Python floats).
_FLOATS = frozenset(np.dtype(t) for t in (np.float16, np.float32, np.float64))

#: A robot's episode is over (terminated) in these statuses; it is ``"running"`` before.
TERMINAL = ("success", "collision")

#: Most lidar beams of an observation vector (each beam is a ray cast at every decision).
MAX_RAYS = 4096
#: Largest magnitude of a reward weight (a larger one is a mistake, and its rewards overflow).
MAX_WEIGHT = 1e6
#: Largest lidar range or goal scale [m] (:data:`uvnav.validation.MAX_COORDINATE`).
MAX_LENGTH = MAX_COORDINATE


def _as_float(name: str, value: Any, what: str) -> float:
    """``value`` as a float (an int beyond float's range: inf); ``TypeError`` naming ``name``
    when it is not a real number (a bool is not one)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(
            f"{name} must be {what} (got {type(value).__name__} {clip(repr(value), 40)})"
        )
    try:
        return float(value)
    except OverflowError:  # an int beyond float's range
        return math.inf


def checked_real(name: str, value: Any, limit: float, *, positive: bool = False) -> float:
    """``value`` as a float when it is a real number (not a bool) with ``|value| <= limit``
    (and ``> 0`` when ``positive``).

    Raises:
        TypeError: not a real number (one line naming ``name``).
        ValueError: NaN, ±inf or beyond ``limit`` (one line naming ``name``).
    """
    v = _as_float(name, value, "a number")
    if positive and not (math.isfinite(v) and 0 < v <= limit):
        raise ValueError(f"{name} must be a finite number > 0 and <= {limit:g} (got {v:g})")
    if not (math.isfinite(v) and abs(v) <= limit):
        raise ValueError(f"{name} must be a finite number within +-{limit:g} (got {v:g})")
    return v


def checked_count(name: str, value: Any, low: int, high: int) -> int:
    """``value`` as an int when it is a whole number (an int, or a float such as 32.0; not a
    bool) from ``low`` to ``high``.

    Raises:
        TypeError: not a number; ValueError: not whole, or out of range (one line naming it).
    """
    v = _as_float(name, value, "a whole number")
    if not (math.isfinite(v) and v.is_integer() and low <= v <= high):
        raise ValueError(
            f"{name} must be a whole number >= {low} and <= {high} (got {clip(repr(value), 40)})"
        )
    return int(v)


def checked_scenario(scenario: Any, kind: type) -> None:
    """Refuse a ``scenario`` argument that is neither a ``kind`` scene nor a name or a path
    (a built-in name, a YAML path or ``generator:seed``).

    Raises:
        TypeError: one line naming the argument and the type given.
    """
    if not isinstance(scenario, kind | str | os.PathLike):
        raise TypeError(
            f"scenario must be a built-in name, a YAML path, GENERATOR:SEED or a {kind.__name__} "
            f"(got {type(scenario).__name__})"
        )


def checked_actions(name: str, actions: Any, shape: tuple[int, ...]) -> np.ndarray:
    """``actions`` as a float array of ``shape`` whose entries are all finite; an env calls it
    before any command is applied, so a refused action changes nothing.

    Raises:
        ValueError: another shape, entries that are not numbers, or NaN/±inf (one line naming
            ``name`` and the first bad entry).
    """
    try:
        a = np.asarray(actions, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(
            f"{name} must be numbers, shape {shape} (got {clip(one_line(repr(actions)), 60)})"
        ) from None
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape} (got {a.shape})")
    if np.isfinite(a).all():
        return a
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):
        where = tuple(int(i) for i in bad[0])
        raise ValueError(
            f"{name}[{', '.join(map(str, where))}] is {a[where]}: an action must be finite"
        )
    return a


@dataclass(frozen=True)
class RewardConfig:
    """Reward weights (see the module docstring).

    Attributes:
        progress: per metre of progress toward the goal.
        time: per decision (a small penalty for dawdling).
        clearance: per metre below ``clearance_margin``.
        clearance_margin: clearance [m] under which the clearance penalty applies.
        success: on arrival.
        collision: on a collision (subtracted).
    """

    progress: float = 1.0
    time: float = 0.01
    clearance: float = 0.5
    clearance_margin: float = 0.3
    success: float = 10.0
    collision: float = 10.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = checked_real(f"reward.{f.name}", getattr(self, f.name), MAX_WEIGHT)
            object.__setattr__(self, f.name, value)
        if self.clearance_margin < 0:
            raise ValueError(
                f"reward.clearance_margin must be >= 0 [m] (got {self.clearance_margin})"
            )

    def reward(self, progress: float, clearance: float, status: str) -> float:
        """One decision's reward: ``progress`` [m] toward the goal, the ``clearance`` [m] over the
        decision, and the episode status after it (``"success"``/``"collision"`` end it)."""
        r = self.progress * progress - self.time
        r -= self.clearance * max(0.0, self.clearance_margin - clearance)
        if status == "success":
            r += self.success
        elif status == "collision":
            r -= self.collision
        return r


class ControllerView:
    """What a uvnav controller is given at this decision: its
    :class:`~uvnav.sensors.Observation` (made by the world's sensor, as in the simulator) and its
    vehicle limits (``info["uvnav"]`` of the envs), whether the env takes raw commands, and the
    planar vehicle when it is not the unicycle (whose commands the action maps).

    ``ControllerView(observation, spec, raw_commands, vehicle)`` holds an observation made;
    :meth:`deferred` one made on the first read of :attr:`observation` from what the world kept
    at the decision (a policy that never reads it never pays for it).  Equality compares the
    contents (numpy arrays element-wise), so Gymnasium's determinism checks can compare infos.
    """

    __slots__ = ("_make", "_observation", "raw_commands", "spec", "vehicle")

    def __init__(
        self,
        observation: Observation,
        spec: Any,
        raw_commands: bool = False,  # the env's action is the command (v, u) itself
        vehicle: Any = None,  # a Vehicle2D other than the unicycle
    ) -> None:
        self._observation: Observation | None = observation
        self._make: Callable[[], Observation] | None = None
        self.spec, self.raw_commands, self.vehicle = spec, raw_commands, vehicle

    @classmethod
    def deferred(
        cls, make: Callable[[], Observation], spec: Any, raw_commands: bool, vehicle: Any
    ) -> ControllerView:
        """A view whose observation is ``make()``, called on the first read only."""
        view = cls.__new__(cls)
        view._observation, view._make = None, make
        view.spec, view.raw_commands, view.vehicle = spec, raw_commands, vehicle
        return view

    @property
    def observation(self) -> Observation:
        """The law's observation at this decision."""
        obs = self._observation
        if obs is None:
            assert self._make is not None
            obs = self._observation = self._make()
            self._make = None
        return obs

    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled (and deep-copied) with its observation made: a vector env's worker sends
        its infos to the main process."""
        return (ControllerView, (self.observation, self.spec, self.raw_commands, self.vehicle))

    def __repr__(self) -> str:
        return (
            f"ControllerView(observation={self.observation!r}, spec={self.spec!r}, "
            f"raw_commands={self.raw_commands!r}, vehicle={self.vehicle!r})"
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ControllerView):
            return NotImplemented
        a, b = self.observation, other.observation
        if self.spec != other.spec or a.time != b.time or a.speed != b.speed:
            return False
        if not (np.array_equal(a.pose, b.pose) and np.array_equal(a.goal, b.goal)):
            return False
        if len(a.obstacles) != len(b.obstacles):
            return False
        return all(
            ra.obstacle_id == rb.obstacle_id
            and ra.distance == rb.distance
            and np.array_equal(ra.centre, rb.centre)
            and np.array_equal(ra.velocity, rb.velocity)
            for ra, rb in zip(a.obstacles, b.obstacles, strict=True)
        )

    __hash__ = None  # type: ignore[assignment]


def action_commands(
    actions: np.ndarray, v_max: np.ndarray, u_max: np.ndarray, raw: bool
) -> tuple[np.ndarray, np.ndarray]:
    """(n, 2) finite actions (:func:`checked_actions`) to unicycle commands ``(v, u)`` [m/s,
    rad/s], (n,) each, before the world saturates them to (2.4): the actions themselves when
    ``raw``, else normalised actions in [-1, 1]^2 (clipped) mapped onto [0, V_max] x [-U_max,
    U_max] (``v_max``, ``u_max``: (n,) limits).  The one rule of :meth:`EnvWorld.command` and
    the batched env.

    >>> v, u = action_commands(np.array([[0.0, -1.0], [3.0, 2.0]]), np.full(2, 1.2),
    ...                        np.full(2, 0.8), raw=False)
    >>> v.tolist(), u.tolist()
    ([0.6, 1.2], [-0.8, 0.8])
    """
    a = np.asarray(actions, dtype=float)
    if raw:
        return a[:, 0], a[:, 1]
    a = np.clip(a, -1.0, 1.0)
    return 0.5 * (a[:, 0] + 1.0) * v_max, a[:, 1] * u_max


def box_command(
    action: np.ndarray, low: tuple[float, float], high: tuple[float, float], raw: bool
) -> tuple[float, float]:
    """A planar vehicle's two command numbers from a finite action (:func:`checked_actions`):
    the action itself when ``raw``, else a normalised action in [-1, 1]^2 (clipped) mapped
    linearly onto the box ``[low, high]``.

    >>> box_command(np.array([0.0, 5.0]), (-2.0, -1.0), (2.0, 1.0), raw=False)
    (0.0, 1.0)
    >>> box_command(np.array([1.0, -1.0]), (-2.0, -1.0), (2.0, 1.0), raw=False)
    (2.0, -1.0)
    """
    a = np.asarray(action, dtype=float)
    if raw:
        return float(a[0]), float(a[1])
    a = np.clip(a, -1.0, 1.0)
    lo, hi = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
    c = lo + 0.5 * (a + 1.0) * (hi - lo)
    return float(c[0]), float(c[1])


class EnvWorld:
    """A loop world stepped one decision at a time, and the env's view of it (module docstring).

    Robot i is agent i of ``world`` (a :class:`World2D` or a :class:`MultiUnicycleWorld`,
    started here as for laws that are not oracles: with ``velocities: estimated`` sensing the
    observations carry estimated rates).

    Args:
        world: a fresh world.
        n_rays: lidar beams in the observation vector.
        max_range: lidar range [m].
        goal_scale: distance [m] mapped to 1 in the observation.
        reward: reward weights.
        raw_commands: actions are commands ``(v, u)`` (module docstring).
    """

    def __init__(
        self,
        world: World2D | MultiUnicycleWorld,
        *,
        n_rays: int = 32,
        max_range: float = 5.0,
        goal_scale: float = 20.0,
        reward: RewardConfig | None = None,
        raw_commands: bool = False,
    ) -> None:
        self.world = world
        self.multi = isinstance(world, MultiUnicycleWorld)
        self.n_rays = int(n_rays)
        self.max_range = float(max_range)
        self.goal_scale = float(goal_scale)
        self.reward = reward or RewardConfig()
        self.raw_commands = raw_commands
        self.k = len(world.obstacles)
        world.start([False] * world.n_agents)
        self.clearance = np.array([self._gap(i) for i in range(self.n)])
        #: the one robot of a World2D, whose bodies may cast the lidar in one compiled call
        self.one = one = world if isinstance(world, World2D) else None
        self._rel = beam_offsets(self.n_rays, 2.0 * np.pi)
        self._ranges = np.empty(self.n_rays)
        #: the one robot's compiled bodies, which cast the lidar in one call
        self._packed = (
            one.bodies if one is not None and isinstance(one.bodies, PackedBodies) else None
        )
        if one is not None and self._packed is not None and one.sensors.exact_only:
            # the law's view senses when it is read (World2D.observe_later), not in every step
            one.sense_in_step = False
        if one is not None:  # what the one robot's step reads, as floats
            self._goal_xy = (float(one.goal[0]), float(one.goal[1]))
            self._unicycle = one.vehicle == "unicycle"
            # v_max for every vehicle; u_max where the vehicle turns (a plug-in's spec may not)
            u_max = getattr(one.spec, "u_max", 0.0) if self._unicycle else 0.0
            self._limits = (float(one.spec.v_max), float(u_max))

    # ----------------------------------------------------------------- robot i of either world
    @property
    def n(self) -> int:
        return self.world.n_agents

    @property
    def field(self) -> ObstacleField:
        """The world's field now (the obstacles first, then, in a multi-robot world, the
        robots)."""
        return self.world.field

    def pose(self, i: int) -> np.ndarray:
        w = self.world
        return w.state[i] if isinstance(w, MultiUnicycleWorld) else w.pose

    def goal(self, i: int) -> np.ndarray:
        w = self.world
        return w.goals[i] if isinstance(w, MultiUnicycleWorld) else w.goal

    def spec(self, i: int) -> Any:
        w = self.world
        return w.robots[i].spec if isinstance(w, MultiUnicycleWorld) else w.spec

    def status(self, i: int) -> str:
        """``"success"``, ``"collision"`` or ``"running"``."""
        w = self.world
        s = w.status[i] if isinstance(w, MultiUnicycleWorld) else w.status
        return s if s in TERMINAL else "running"

    def running(self, i: int) -> bool:
        return self.status(i) == "running"

    def speed(self, i: int) -> float:
        """The speed held now [m/s] (0 once the robot's episode is over)."""
        w = self.world
        if not self.running(i):
            return 0.0
        return float(w.applied[i].v if isinstance(w, MultiUnicycleWorld) else w.speed)

    def _gap(self, i: int) -> float:
        """Robot i's gap after the last step [m] (``max_range`` when nothing is within reach)."""
        w = self.world
        c = float(w.clearance[i] if isinstance(w, MultiUnicycleWorld) else w.clearance)
        return c if math.isfinite(c) else self.max_range

    def distance(self, i: int) -> float:
        """Robot i's distance to its goal [m]."""
        one = self.one
        if one is not None:
            gx, gy = self._goal_xy
            return math.hypot(gx - one.x, gy - one.y)
        x, y = (float(p) for p in self.pose(i)[:2])
        goal = self.goal(i)
        return math.hypot(float(goal[0]) - x, float(goal[1]) - y)

    # ------------------------------------------------------------------------ what the env adds
    def obs_size(self) -> int:
        return 4 + self.n_rays

    def view(self, i: int) -> ControllerView:
        """Robot i's :class:`ControllerView`: the world's observation (call once per decision:
        an estimator, a noisy lidar, advance with it) and its limits.  A :class:`World2D`'s is
        made when first read (:meth:`~uvnav.sim.episode.World2D.observe_later`)."""
        w = self.world
        if isinstance(w, World2D):
            body = w.body if w.vehicle != "unicycle" else None
            return ControllerView.deferred(w.observe_later(i), w.spec, self.raw_commands, body)
        return ControllerView(w.observe(i), self.spec(i), self.raw_commands)

    def vector(self, i: int) -> np.ndarray:
        """Robot i's observation vector (module docstring), float32."""
        one = self.one
        if one is not None:
            return self._vector_one(one)
        x, y, th = (float(p) for p in self.pose(i))
        goal = self.goal(i)
        gx, gy = float(goal[0]) - x, float(goal[1]) - y
        bearing = math.atan2(gy, gx) - th
        out = np.empty(self.obs_size(), dtype=np.float32)
        out[0] = min(math.hypot(gx, gy) / self.goal_scale, 1.0)
        out[1] = math.cos(bearing)
        out[2] = math.sin(bearing)
        out[3] = min(max(self.speed(i) / self.spec(i).v_max, 0.0), 1.0)
        # clipped in [0, 1] after the cast to float32: the same numbers (0 and 1 are exact)
        scaled = out[4:]
        np.divide(self.ranges(i), self.max_range, out=scaled)
        np.minimum(np.maximum(scaled, 0.0, out=scaled), 1.0, out=scaled)
        return out

    def _vector_one(self, one: World2D) -> np.ndarray:
        """:meth:`vector` of the one robot of a :class:`World2D`: the same operations on the
        floats kept at the start (for packed bodies, in one compiled call)."""
        x, y, th = one.x, one.y, one.th
        speed = 0.0 if one.book.status in TERMINAL else float(one.speed)
        out = np.empty(4 + self.n_rays, dtype=np.float32)
        packed = self._packed
        if packed is not None:
            packed.vector((x, y, th), self._goal_xy, self.goal_scale, speed, self._limits[0],
                          self._rel, self.max_range, self._ranges, out)  # fmt: skip
            return out
        gx, gy = self._goal_xy[0] - x, self._goal_xy[1] - y
        bearing = math.atan2(gy, gx) - th
        out[0] = min(math.hypot(gx, gy) / self.goal_scale, 1.0)
        out[1] = math.cos(bearing)
        out[2] = math.sin(bearing)
        out[3] = min(max(speed / self._limits[0], 0.0), 1.0)
        scaled = out[4:]
        np.divide(self.ranges(0), self.max_range, out=scaled)
        np.minimum(np.maximum(scaled, 0.0, out=scaled), 1.0, out=scaled)
        return out

    def ranges(self, i: int) -> np.ndarray:
        """Robot i's lidar ranges [m] now (:func:`~uvnav.sensors.exact.lidar_scan` without
        noise; for packed bodies the same numbers from one compiled call)."""
        one, packed = self.one, self._packed
        if one is not None and packed is not None:
            packed.lidar(one.x, one.y, one.th, self._rel, self.max_range, self._ranges)
            return self._ranges
        field = self._lidar_field(i)
        return lidar_scan(self.pose(i), field, n_rays=self.n_rays, max_range=self.max_range).ranges

    def _lidar_field(self, i: int) -> ObstacleField:
        """The field robot i's lidar sees: everything but its own disc."""
        w = self.world
        return w.field_seen_by(i) if isinstance(w, MultiUnicycleWorld) else w.field

    def action_name(self, i: int) -> str:
        """How errors name robot ``i``'s action."""
        return f"action of robot_{i}" if self.multi else "action"

    def command(self, i: int, action: np.ndarray) -> Any:
        """The command of robot ``i``'s action: a unicycle's by :func:`action_commands`,
        another vehicle's by :func:`box_command`."""
        w = self.world
        a = np.asarray(action, dtype=float).reshape(1, 2)
        if isinstance(w, World2D) and w.vehicle != "unicycle":
            return w.body.command(*box_command(a[0], *w.body.bounds(), self.raw_commands))
        spec = self.spec(i)
        a0, a1 = float(a[0, 0]), float(a[0, 1])
        if self.raw_commands:
            return UnicycleCommand(a0, a1)
        # action_commands on one pair, in floats: the same operations in the same order
        a0, a1 = min(max(a0, -1.0), 1.0), min(max(a1, -1.0), 1.0)
        return UnicycleCommand(0.5 * (a0 + 1.0) * float(spec.v_max), a1 * float(spec.u_max))

    def rest(self, i: int) -> Any:
        """Robot ``i``'s command when it has no action: standing still."""
        w = self.world
        return w.body.rest() if isinstance(w, World2D) else UnicycleCommand(0.0, 0.0)

    def step(self, actions: dict[int, np.ndarray]) -> np.ndarray:
        """One decision: the acting robots' commands (a robot without an action stands still)
        are applied, then the world advances to the next decision time or the end.  Returns the
        rewards (0 for robots that were already done)."""
        n, w = self.n, self.world
        if self.one is not None:
            return np.array([self.step_one(actions.get(0))])
        actions = {i: checked_actions(self.action_name(i), a, (2,)) for i, a in actions.items()}
        before = [self.distance(i) for i in range(n)]
        was_running = [self.running(i) for i in range(n)]
        low = np.full(n, np.inf)
        if not w.done:
            for i in w.acting():
                cmd = self.command(i, actions[i]) if i in actions else self.rest(i)
                w.apply(cmd, i)
            while True:
                alive = [i for i in range(n) if self.running(i)]
                w.advance()
                for i in alive:
                    low[i] = min(low[i], self._gap(i))
                if w.done or w.acting():
                    break
        rewards = np.zeros(n)
        for i in range(n):
            if not was_running[i]:
                continue
            if math.isfinite(low[i]):
                self.clearance[i] = low[i]
            rewards[i] = self.reward.reward(
                before[i] - self.distance(i), float(self.clearance[i]), self.status(i)
            )
        return rewards

    def step_one(self, action: Any) -> float:
        """:meth:`step` for the one robot of a :class:`World2D`: its action (``None``: it
        stands still) applied, the world advanced to the next decision; returns the reward (0
        once the robot's episode is over)."""
        w = self.one
        assert w is not None
        cmd = self.rest(0) if action is None else self._command_one(w, action)
        book, clock = w.book, w.clock
        before = self.distance(0)
        was_running = book.status not in TERMINAL
        low = math.inf
        if not w.done:
            if clock.due:
                w.apply(cmd)
            while True:
                alive = book.status not in TERMINAL
                w.advance()
                if alive:
                    c = w.clearance
                    low = min(low, c if math.isfinite(c) else self.max_range)
                if w.done or clock.due:
                    break
        if not was_running:
            return 0.0
        if math.isfinite(low):
            self.clearance[0] = low
        status = book.status if book.status in TERMINAL else "running"
        return self.reward.reward(before - self.distance(0), float(self.clearance[0]), status)

    def _command_one(self, w: World2D, action: Any) -> Any:
        """The one robot's command of ``action`` (checked as :func:`checked_actions` checks
        it): :meth:`command`'s numbers, read from a float array of two finite entries without
        the checks' array."""
        if type(action) is np.ndarray and action.dtype in _FLOATS and action.shape == (2,):
            a0, a1 = action.tolist()
            if math.isfinite(a0) and math.isfinite(a1) and self._unicycle:
                if self.raw_commands:
                    return UnicycleCommand(a0, a1)
                if not -1.0 <= a0 <= 1.0:  # (clipped: the same numbers as min(max(...)))
                    a0 = min(max(a0, -1.0), 1.0)
                if not -1.0 <= a1 <= 1.0:
                    a1 = min(max(a1, -1.0), 1.0)
                v_max, u_max = self._limits
                return UnicycleCommand(0.5 * (a0 + 1.0) * v_max, a1 * u_max)
        return self.command(0, checked_actions("action", action, (2,)))

    def info_one(self) -> dict[str, Any]:
        """The one robot's ``info`` (:meth:`EnvWorldEnv._info`)."""
        w = self.one
        assert w is not None
        status = w.book.status
        return {
            "status": status if status in TERMINAL else "running",
            "distance": self.distance(0),
            "clearance": float(self.clearance[0]),
            "time": w.t,
            "uvnav": self.view(0),
        }

    def close(self) -> None:
        """Write the obstacles' states back (the world's :meth:`close`)."""
        self.world.close()


class EnvWorldEnv:
    """What ``uvnav/Nav2D-v0`` and the multi-robot env (:mod:`uvnav.envs.multi_robot`) share
    over their :class:`EnvWorld`: the lidar, reward and action options, opening a world at reset,
    robot i's ``info``, rendering and closing."""

    render_mode: str | None
    goal_scale: float

    def _configure(
        self,
        render_mode: str | None,
        n_rays: int,
        max_range: float,
        reward: RewardConfig,
        raw_commands: bool,
    ) -> None:
        self.render_mode = render_mode
        self.n_rays, self.max_range = checked_lidar(n_rays, max_range)
        self.reward_config = reward
        self.raw_commands = raw_commands
        self._world: EnvWorld | None = None
        self._bounds = (0.0, 0.0, 1.0, 1.0)
        self.episode_seed: int | None = None

    def _open(self, world: World2D | MultiUnicycleWorld) -> EnvWorld:
        """Step ``world`` (fresh, of the episode ``reset`` starts) from now on."""
        self._world = w = EnvWorld(
            world,
            n_rays=self.n_rays,
            max_range=self.max_range,
            goal_scale=self.goal_scale,
            reward=self.reward_config,
            raw_commands=self.raw_commands,
        )
        self._bounds = scene_bounds(w)
        return w

    def _loop_world(self) -> World2D | MultiUnicycleWorld:
        if self._world is None:
            raise RuntimeError("call reset() first")
        return self._world.world

    def _info(self, i: int) -> dict[str, Any]:
        w = self._world
        assert w is not None
        if w.one is not None:
            return w.info_one()
        return {
            "status": w.status(i),
            "distance": w.distance(i),
            "clearance": float(w.clearance[i]),
            "time": w.world.t,
            "uvnav": w.view(i),
        }

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array" or self._world is None:
            return None
        return render_frame(self._world, self._bounds)

    def close(self) -> None:
        if self._world is not None:
            self._world.close()
            self._world = None


def checked_lidar(n_rays: Any, max_range: Any) -> tuple[int, float]:
    """An env's lidar: ``n_rays`` (a whole number from 0 to :data:`MAX_RAYS`) and ``max_range``
    [m] (> 0 and at most :data:`MAX_LENGTH`).

    Raises:
        TypeError: either is not a number; ValueError: either is out of range (one line naming
            it).
    """
    rays = checked_count("n_rays", n_rays, 0, MAX_RAYS)
    return rays, checked_real("max_range", max_range, MAX_LENGTH, positive=True)


def goal_scale_for(distance: float, goal_scale: float | None) -> float:
    """The distance [m] an observation maps to 1: ``goal_scale`` when given, else 1.5 x the
    scene's start-goal ``distance`` [m] (at least 1 m), the default of every uvnav env."""
    if goal_scale is None:
        return max(1.5 * distance, 1.0)
    return checked_real("goal_scale", goal_scale, MAX_LENGTH, positive=True)


def scene_bounds(world: EnvWorld, margin: float = 1.5) -> tuple[float, float, float, float]:
    """A box [m] around the robots' starts and goals and the obstacles' initial bounding discs
    (pedestrians parked far away are left out), grown by ``margin``; call it at reset."""
    starts = np.array([world.pose(i)[:2] for i in range(world.n)])
    pts = [starts, np.array([world.goal(i) for i in range(world.n)])]
    if world.k:
        one = world.one
        c = (one.bodies.centres()[0] if one is not None else world.world.field.centres)[: world.k]
        rad = world.world.template.bounding_radii[: world.k]
        near = np.hypot(*(c - starts[0]).T) < 100.0
        if near.any():
            pts += [c[near] - rad[near, None], c[near] + rad[near, None]]
    return square_bounds(np.vstack(pts), margin)


def square_bounds(points: np.ndarray, margin: float) -> tuple[float, float, float, float]:
    """The smallest square ``(xmin, ymin, xmax, ymax)`` [m] around ``points`` (n, 2), grown by
    ``margin`` [m]."""
    lo = points.min(axis=0) - margin
    hi = points.max(axis=0) + margin
    side = float(max(hi - lo))
    mid = 0.5 * (lo + hi)
    return (mid[0] - side / 2, mid[1] - side / 2, mid[0] + side / 2, mid[1] + side / 2)


def pixel_grid(
    bounds: tuple[float, float, float, float], width: int, height: int
) -> tuple[np.ndarray, np.ndarray]:
    """Pixel-centre coordinates [m] of a ``height`` x ``width`` frame over ``bounds``
    ``(xmin, ymin, xmax, ymax)``, y up."""
    xmin, ymin, xmax, ymax = bounds
    xs = xmin + (np.arange(width) + 0.5) * (xmax - xmin) / width
    ys = ymax - (np.arange(height) + 0.5) * (ymax - ymin) / height
    gx, gy = np.meshgrid(xs, ys)
    return gx, gy


ROBOT_COLOURS = np.array(
    [
        [31, 119, 180],
        [214, 39, 40],
        [44, 160, 44],
        [148, 103, 189],
        [255, 127, 14],
        [140, 86, 75],
        [227, 119, 194],
        [23, 190, 207],
    ],
    dtype=np.uint8,
)


def render_frame(
    world: EnvWorld, bounds: tuple[float, float, float, float], size: int = 256
) -> np.ndarray:
    """An RGB frame (size, size, 3) uint8 of the world: obstacles grey, robots coloured discs,
    goals coloured squares; y up.  Pure numpy + shapely (no plotting library)."""
    import shapely

    xmin, ymin, xmax, ymax = bounds
    img = np.full((size, size, 3), 255, dtype=np.uint8)
    gx, gy = pixel_grid(bounds, size, size)
    f = world.field
    for j in range(world.k):
        c = f.centres[j]
        r = float(f.bounding_radii[j])
        if c[0] + r < xmin or c[0] - r > xmax or c[1] + r < ymin or c[1] - r > ymax:
            continue
        poly = f.polygons[j]
        if poly is None:
            mask = np.hypot(gx - c[0], gy - c[1]) <= float(f.radii[j])
        else:
            mask = shapely.contains_xy(shapely.Polygon(poly), gx, gy)
        img[mask] = (120, 120, 120)
    px = (xmax - xmin) / size
    for i in range(world.n):
        col = ROBOT_COLOURS[i % len(ROBOT_COLOURS)]
        g = world.goal(i)
        img[(np.abs(gx - g[0]) <= 2.5 * px) & (np.abs(gy - g[1]) <= 2.5 * px)] = col
        x, y, th = (float(c) for c in world.pose(i))
        rad = max(float(world.spec(i).radius), 2.0 * px)
        img[np.hypot(gx - x, gy - y) <= rad] = col
        tip = np.hypot(gx - (x + rad * math.cos(th)), gy - (y + rad * math.sin(th))) <= 1.5 * px
        img[tip] = (0, 0, 0)
    return img
