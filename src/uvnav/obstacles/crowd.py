"""Pedestrians that walk by their own ORCA policy: one crowd, one RVO2 simulator.

The ``orca`` pedestrians of the crowd-navigation benchmarks (Chen, Liu, Kreiss, Alahi, "Crowd-robot
interaction: crowd-aware robot navigation with attention-based deep reinforcement learning",
ICRA 2019, arXiv:1809.08835; simulator CrowdSim of https://github.com/vita-epfl/CrowdNav, studied
for this module, not copied).  Each pedestrian has a goal and a preferred speed; every decision
period the crowd's velocities are chosen by ORCA (van den Berg, Guy, Lin, Manocha, ISRR 2009)
through RVO2 (``pyrvo``), each pedestrian avoiding the others reciprocally, and held over the
period.

**The robot is invisible by default** (CrowdNav's test protocol, ``[robot] visible = false`` in
its ``env.config``): pedestrians react to each other only, and a crowd is an ordinary obstacle
motion model.  **A visible robot** (``sees_robot``, CrowdNav's ``visible = true``): the world
tells the crowd where the robot is before every step (:meth:`Crowd.see_robot`, through
:meth:`uvnav.obstacles.ObstacleBatch.see_robot`), and at each decision the robot is one more RVO2
agent at its position with its velocity as current and preferred velocity (its new velocity is
discarded: the law moves it), so the pedestrians avoid it as CrowdNav's ORCA humans avoid a
visible robot, reciprocally (they take half of each avoidance, expecting the robot to take the
other half).  A crowd sees the robot when any of its members is set to.

What is implemented, with its source in CrowdNav (``crowd_sim/envs/policy/orca.py``,
``crowd_sim/envs/crowd_sim.py``, ``crowd_sim/envs/utils/agent.py``):

* *One simulator per crowd.*  CrowdNav gives every human its own RVO2 simulator, in which it is
  agent 0 and the others are agents at their observed positions and velocities; the velocity RVO2
  computes for an agent depends only on its own position, velocity, preferred velocity, radius and
  maximum speed and on its neighbours' positions, velocities and radii, so one simulator holding
  the whole crowd (positions and velocities set from the crowd's state before each ``do_step``)
  computes the same velocities.  RVO2 works in float32; as in CrowdNav the positions are kept in
  float64 here and integrated as ``p += v dt`` with the velocity RVO2 returns.
* *Parameters* (``ORCA.__init__``): neighbour distance 10 m, at most 10 neighbours, time horizon
  5 s, time horizon for obstacles 5 s (unused: no static obstacles), maximum speed = the
  pedestrian's ``v_pref`` (1 m/s in ``env.config``), RVO2 radius = body radius (0.3 m) + 0.01 m
  (``radius + 0.01 + safety_space``, ``safety_space`` 0 for the humans): :data:`SAFETY_MARGIN`.
* *Preferred velocity* (``ORCA.predict``): toward the goal, of norm 1 m/s beyond 1 m from it and
  equal to the gap (m read as m/s) within it, so the pedestrian slows down and settles on its
  goal.  Here, for any ``v_pref``: ``v_pref`` toward the goal beyond ``v_pref`` x 1 s from it, the
  gap within (CrowdNav's rule for its ``v_pref`` = 1; CrowdNav itself keeps the 1 m threshold and
  lets RVO2 clip to ``v_pref``).
* *At the goal* (``CrowdSim.step``, test phase): nothing special happens; the human keeps running
  ORCA toward its goal, so it stops there (preferred velocity ~ 0) but still steps aside for the
  others (CrowdNav's docstring: "Agent doesn't stop moving after it reaches the goal, because once
  it stops moving, the reciprocal rule is broken").  No new goal is drawn (CrowdNav's circle
  crossing draws none).  That is what is implemented by default.
* *Goal changes* (optional, for harder crowds; CrowdNav++'s randomly changing goals, Liu et al.,
  ICRA 2023): a pedestrian may hold further goals (``next_goals``), walked to in order; it moves
  on to the next one at each of its ``change_times`` (goals changed at random times, drawn by the
  scene) and, when ``arrival`` > 0, as soon as its centre is within ``arrival`` of the current
  goal (a pedestrian that arrives sets off again).  The switch is looked at when the crowd
  decides, from the state it decides on; the last goal is kept.
* *Timing* (``CrowdSim.step``): all actions are computed from the state at t, then all agents
  move; pedestrians start at rest (``human.set(px, py, gx, gy, 0, 0, 0)``).  Here a decision is
  taken every ``period`` [s] (CrowdNav's time step 0.25 s; ``None`` = every integration step) and
  the velocity held in between, so a finer integration step only refines the collision checks.

Determinism and the two paths: every :class:`OrcaPedestrian` of a crowd holds a reference to one
shared :class:`Crowd`; the first ``step(state, t, dt)`` of a time step advances the crowd once and
every member reads its row, and :class:`CrowdGroup` (the batched path of
:class:`~uvnav.obstacles.ObstacleBatch`) makes the same single call, so both paths give the same
states bit for bit.  RVO2 draws nothing at random: the same start gives the same trajectory.
The crowd owns its pedestrians' positions: the ``state`` handed to ``step`` supplies only the
heading (kept: a disc pedestrian does not rotate, ``angular_velocity`` 0).

:class:`OrcaWanderer` is a crowd member without a goal: its preferred velocity is what a
:class:`~uvnav.obstacles.motion.RandomTurn` wandering takes from its actual state, so randomly
wandering bodies (any body: ORCA sees its bounding disc) avoid each other (``random-ch2``'s
``mutual_avoidance``); each member's :meth:`OrcaPedestrian.preferred` gives its preferred velocity.

Models are built unattached (:meth:`OrcaPedestrian`), then :func:`join_crowds` gathers the
pedestrians of an obstacle list by crowd id and builds their shared crowd from the obstacles'
initial states and body radii; :class:`~uvnav.obstacles.ObstacleBatch` calls it, and a per-model
``step`` loop must call it first.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.motion import ObstacleState, RandomTurn
from uvnav.obstacles.obstacle import Obstacle

#: CrowdNav's ORCA defaults (``crowd_sim/envs/policy/orca.py``)
NEIGHBOR_DIST = 10.0  # [m]
MAX_NEIGHBORS = 10
TIME_HORIZON = 5.0  # [s]
TIME_HORIZON_OBST = 5.0  # [s]
#: added to the body radius for RVO2 (CrowdNav's ``radius + 0.01 + safety_space``) [m]
SAFETY_MARGIN = 0.01
V_PREF = 1.0  # [m/s]
#: default crowd id (one crowd per scene unless pedestrians name another)
DEFAULT_CROWD = "crowd"

#: a decision is due when ``t >= next decision - _TIME_EPS`` [s]
_TIME_EPS = 1e-9


def _import_pyrvo() -> Any:
    try:
        import pyrvo
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "orca_crowd pedestrians need the RVO2 bindings 'pyrvo'; install the extra: "
            "pip install 'uvnav[bench]' (or pip install 'pyrvo==0.4.3')"
        ) from exc
    return pyrvo


def preferred_velocity(
    position: FloatArray, goal: FloatArray, v_pref: float
) -> tuple[float, float]:
    """``v_pref`` toward ``goal`` beyond ``v_pref`` x 1 s from it, the gap itself within [m/s].

    >>> preferred_velocity(np.zeros(2), np.array([3.0, 4.0]), 1.0)
    (0.6, 0.8)
    >>> preferred_velocity(np.zeros(2), np.array([0.5, 0.0]), 1.0)
    (0.5, 0.0)
    """
    gx = float(goal[0]) - float(position[0])
    gy = float(goal[1]) - float(position[1])
    d = math.hypot(gx, gy)
    if d > v_pref:
        return gx / d * v_pref, gy / d * v_pref
    return gx, gy


class CrowdMember:
    """What every pedestrian of a crowd shares, whatever the crowd's policy (ORCA here, social
    force in :mod:`uvnav.obstacles.social_force`): a reference to its crowd and its row there,
    a ``step`` that advances the crowd once per time step and reads the row, and the batched
    group.  A subclass is a dataclass with the fields ``crowd_id``, ``crowd`` and ``index`` and a
    classmethod :meth:`make_crowd`."""

    crowd_id: str
    crowd: Any
    index: int

    @classmethod
    def make_crowd(
        cls,
        members: Sequence[Any],
        positions: FloatArray,
        velocities: FloatArray,
        radii: Sequence[float],
    ) -> Any:
        """The shared state of a crowd of ``members`` (from their obstacles' states)."""
        raise NotImplementedError

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState:
        crowd = self.crowd
        if crowd is None:
            raise RuntimeError(
                f"{type(self).__name__} not in a crowd: call "
                "uvnav.obstacles.crowd.join_crowds(obstacles) before stepping the models one by "
                "one (ObstacleBatch does it)"
            )
        crowd.advance(t, dt)
        i = self.index
        return ObstacleState(
            position=crowd.position[i].copy(),
            heading=state.heading,
            velocity=crowd.velocity[i].copy(),
            angular_velocity=0.0,
        )

    def turn_bound(self) -> float:
        """0: a disc pedestrian does not rotate."""
        return 0.0

    @classmethod
    def batch_group(cls, models: Sequence[Any]) -> CrowdGroup:
        """The pedestrians advanced together (:class:`~uvnav.obstacles.motion.MotionGroup`)."""
        return CrowdGroup(models)


@dataclass
class OrcaPedestrian(CrowdMember):
    """One pedestrian of an ORCA crowd (module docstring).

    Attributes:
        goal: where it walks to [m], shape (2,).
        v_pref: preferred (and largest) speed [m/s].
        crowd_id: pedestrians with the same id form one crowd.
        neighbor_dist: RVO2 neighbour distance, centre to centre [m].
        max_neighbors: RVO2's largest number of neighbours.
        time_horizon: ORCA's horizon for other pedestrians [s].
        time_horizon_obst: ORCA's horizon for static obstacles [s] (none here).
        safety_margin: added to the body radius for RVO2 [m].
        period: decision period [s] (every integration step when ``None``); one value per crowd.
        sees_robot: the robot is an agent of the crowd's ORCA (module docstring).
        next_goals: (k, 2) the goals after ``goal``, in order [m] (module docstring, goal
            changes).
        change_times: ascending times [s] at which the pedestrian moves on to its next goal.
        arrival: within this distance of its goal it moves on to the next [m] (0: never).
    """

    goal: FloatArray
    v_pref: float = V_PREF
    crowd_id: str = DEFAULT_CROWD
    neighbor_dist: float = NEIGHBOR_DIST
    max_neighbors: int = MAX_NEIGHBORS
    time_horizon: float = TIME_HORIZON
    time_horizon_obst: float = TIME_HORIZON_OBST
    safety_margin: float = SAFETY_MARGIN
    period: float | None = None
    sees_robot: bool = False
    next_goals: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    change_times: FloatArray = field(default_factory=lambda: np.zeros(0))
    arrival: float = 0.0
    crowd: Crowd | None = field(default=None, init=False, repr=False)
    index: int = field(default=-1, init=False, repr=False)
    _leg: int = field(default=0, init=False, repr=False)
    _changed: int = field(default=0, init=False, repr=False)

    def __post_init__(self) -> None:
        self.goal = np.asarray(self.goal, dtype=float).reshape(2)
        self.next_goals = np.asarray(self.next_goals, dtype=float).reshape(-1, 2)
        self.change_times = np.asarray(self.change_times, dtype=float).reshape(-1)
        if not (math.isfinite(self.v_pref) and self.v_pref > 0):
            raise ValueError(f"v_pref must be > 0 (got {self.v_pref!r})")
        if self.period is not None and not (math.isfinite(self.period) and self.period > 0):
            raise ValueError(f"period must be > 0 (got {self.period!r})")
        if not (math.isfinite(self.arrival) and self.arrival >= 0):
            raise ValueError(f"arrival must be >= 0 (got {self.arrival!r})")

    def current_goal(self, position: FloatArray, t: float) -> FloatArray:
        """The goal [m] at ``t`` [s] from ``position`` [m], after the changes due by then
        (module docstring, goal changes)."""
        last = len(self.next_goals)
        times = self.change_times
        while self._changed < len(times) and t >= times[self._changed] - _TIME_EPS:
            self._changed += 1
            self._leg = min(self._leg + 1, last)
        goal = self.goal if self._leg == 0 else self.next_goals[self._leg - 1]
        if self.arrival > 0 and self._leg < last:
            gap = math.hypot(float(goal[0]) - float(position[0]), float(goal[1]) - position[1])
            if gap <= self.arrival:
                self._leg += 1
                goal = self.next_goals[self._leg - 1]
        return goal

    def speed_bound(self) -> float:
        """``v_pref``: RVO2's maximum speed."""
        return float(self.v_pref)

    def preferred(
        self, position: FloatArray, velocity: FloatArray, t: float, period: float
    ) -> tuple[float, float]:
        """The preferred velocity [m/s] at ``t`` [s] for the next ``period`` [s]: toward the
        goal (:func:`preferred_velocity`; :meth:`current_goal`)."""
        if len(self.next_goals) == 0:
            return preferred_velocity(position, self.goal, float(self.v_pref))
        return preferred_velocity(position, self.current_goal(position, t), float(self.v_pref))

    @classmethod
    def make_crowd(
        cls,
        members: Sequence[Any],
        positions: FloatArray,
        velocities: FloatArray,
        radii: Sequence[float],
    ) -> Crowd:
        return Crowd(members, positions, velocities, radii)


@dataclass
class OrcaWanderer(OrcaPedestrian):
    """A body of a crowd that wanders instead of walking to a goal: its preferred velocity is
    the velocity a :class:`~uvnav.obstacles.motion.RandomTurn` would take from the body's actual
    position and velocity (a speed and a course turn rate drawn every ``change_period``, the
    course turned back inside the arena), and ORCA (RVO2, reciprocal, on the bodies' bounding
    discs) bends it so that the bodies of the crowd do not collide.  The body does not rotate
    (``u_i`` = 0).  ``v_pref`` is the largest wandering speed.

    Attributes:
        wander: the wandering that proposes the preferred velocity (draws from its own ``rng``).
    """

    wander: RandomTurn | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.wander is None:
            raise ValueError("an orca wanderer needs its wander (a RandomTurn)")

    def preferred(
        self, position: FloatArray, velocity: FloatArray, t: float, period: float
    ) -> tuple[float, float]:
        """The wandering's velocity over the next ``period`` [s] from the state at ``t`` [s]."""
        assert self.wander is not None
        state = ObstacleState(position=np.array(position, dtype=float), heading=0.0,
                              velocity=np.array(velocity, dtype=float))  # fmt: skip
        v = self.wander.step(state, t, period).velocity
        return float(v[0]), float(v[1])


class Crowd:
    """The shared state of one crowd: positions and velocities in float64, one RVO2 simulator.

    Args:
        members: the pedestrians' models, in crowd order (row ``i`` is ``members[i]``).
        positions: (n, 2) initial positions [m].
        velocities: (n, 2) initial velocities [m/s].
        radii: (n,) body radii [m].
    """

    def __init__(
        self,
        members: Sequence[OrcaPedestrian],
        positions: FloatArray,
        velocities: FloatArray,
        radii: Sequence[float],
    ) -> None:
        self.members = list(members)
        n = len(self.members)
        periods = {m.period for m in self.members}
        if len(periods) > 1:
            raise ValueError(f"one crowd, one decision period (got {sorted(map(str, periods))})")
        self.period = periods.pop() if periods else None
        self.position = np.array(positions, dtype=float).reshape(n, 2)
        self.velocity = np.array(velocities, dtype=float).reshape(n, 2)
        self.radii = [float(r) for r in radii]
        self._held = self.velocity.copy()  # the velocities chosen at the last decision
        self._next_decision = -math.inf
        self._from: float | None = None  # start time of the last step taken
        self._dt: float | None = None
        self._sim: Any = None
        self.decisions = 0
        self.sees_robot = any(m.sees_robot for m in self.members)
        #: the robot as last seen: (position (2,), velocity (2,), radius) [m, m/s, m]
        self.robot: tuple[FloatArray, FloatArray, float] | None = None
        self._robot_agent = -1

    def see_robot(self, position: FloatArray, velocity: FloatArray, radius: float) -> None:
        """The robot's state now (a visible robot is an agent at the next decision)."""
        if self.sees_robot:
            self.robot = (
                np.array(position[:2], dtype=float),
                np.array(velocity[:2], dtype=float),
                float(radius),
            )

    def __len__(self) -> int:
        return len(self.members)

    def _simulator(self, period: float) -> Any:
        if self._sim is None:
            pyrvo = _import_pyrvo()
            sim = pyrvo.RVOSimulator()
            sim.set_time_step(float(period))
            for i, m in enumerate(self.members):
                sim.add_agent(
                    (float(self.position[i, 0]), float(self.position[i, 1])),
                    float(m.neighbor_dist),
                    int(m.max_neighbors),
                    float(m.time_horizon),
                    float(m.time_horizon_obst),
                    self.radii[i] + float(m.safety_margin),
                    float(m.v_pref),
                    (float(self.velocity[i, 0]), float(self.velocity[i, 1])),
                )
            if self.sees_robot:
                m0 = self.members[0] if self.members else OrcaPedestrian(np.zeros(2))
                self._robot_agent = sim.add_agent(
                    (0.0, 0.0), float(m0.neighbor_dist), int(m0.max_neighbors),
                    float(m0.time_horizon), float(m0.time_horizon_obst), 0.0, 1.0, (0.0, 0.0),
                )  # fmt: skip
            self._sim = sim
        elif self._sim.get_time_step() != np.float32(period):
            self._sim.set_time_step(float(period))
        return self._sim

    def _decide(self, t: float, period: float) -> None:
        """Every pedestrian's ORCA velocity for the state at ``t`` [s] (all from the same
        state)."""
        sim = self._simulator(period)
        pos, vel = self.position, self.velocity
        for i, m in enumerate(self.members):
            sim.set_agent_position(i, (float(pos[i, 0]), float(pos[i, 1])))
            sim.set_agent_velocity(i, (float(vel[i, 0]), float(vel[i, 1])))
            sim.set_agent_pref_velocity(i, m.preferred(pos[i], vel[i], t, period))
        if self._robot_agent >= 0:
            self._place_robot(sim)
        sim.do_step()
        held = np.empty_like(self._held)
        for i in range(len(self.members)):  # (the robot's own agent is read by nobody)
            v = sim.get_agent_velocity(i)
            held[i, 0] = float(v.x)
            held[i, 1] = float(v.y)
        self._held = held
        self.decisions += 1

    def _place_robot(self, sim: Any) -> None:
        """The robot's agent at its last seen state (far away and still before it is seen)."""
        k = self._robot_agent
        if self.robot is None:
            sim.set_agent_position(k, (1e6, 1e6))
            sim.set_agent_velocity(k, (0.0, 0.0))
            sim.set_agent_pref_velocity(k, (0.0, 0.0))
            return
        p, v, r = self.robot
        speed = max(float(math.hypot(v[0], v[1])), 1e-6)
        sim.set_agent_radius(k, r + float(self.members[0].safety_margin if self.members else 0.0))
        sim.set_agent_max_speed(k, speed)
        sim.set_agent_position(k, (float(p[0]), float(p[1])))
        sim.set_agent_velocity(k, (float(v[0]), float(v[1])))
        sim.set_agent_pref_velocity(k, (float(v[0]), float(v[1])))

    def advance(self, t: float, dt: float) -> None:
        """Advance the crowd from ``t`` [s] by ``dt`` [s], once: later calls for the same step
        (the other members') return at once."""
        if self._from == t and self._dt == dt:
            return
        period = dt if self.period is None else self.period
        if self.members and t >= self._next_decision - _TIME_EPS:
            self._decide(t, period)
            base = t if self._next_decision == -math.inf else self._next_decision
            self._next_decision = base + period
            while self._next_decision <= t + _TIME_EPS:  # a step longer than the period
                self._next_decision += period
        self.velocity = self._held.copy()
        self.position = self.position + self._held * dt
        self._from = t
        self._dt = dt


class CrowdGroup:
    """The crowd pedestrians of an :class:`~uvnav.obstacles.ObstacleBatch`: each crowd advanced
    once per step, every member's row read (bit for bit the models' ``step``)."""

    def __init__(self, models: Sequence[CrowdMember]) -> None:
        for m in models:
            if m.crowd is None:
                raise RuntimeError("pedestrian not in a crowd: call join_crowds(obstacles)")
        self.models = list(models)
        self.crowds: list[Any] = []
        for m in self.models:
            if not any(c is m.crowd for c in self.crowds):
                self.crowds.append(m.crowd)
        # per crowd: the group's columns of its members and their rows in the crowd
        self.rows = [
            (
                np.array([j for j, m in enumerate(self.models) if m.crowd is c], dtype=np.intp),
                np.array([m.index for m in self.models if m.crowd is c], dtype=np.intp),
            )
            for c in self.crowds
        ]

    def step(
        self, position: FloatArray, heading: FloatArray, t: float, dt: float
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        m = len(self.models)
        pos = np.empty((2, m))
        vel = np.empty((2, m))
        for c, (cols, rows) in zip(self.crowds, self.rows, strict=True):
            c.advance(t, dt)
            pos[:, cols] = c.position[rows].T
            vel[:, cols] = c.velocity[rows].T
        return pos, np.array(heading, dtype=float), vel, np.zeros(m)


def join_crowds(obstacles: Sequence[Obstacle]) -> list[Any]:
    """Gather the crowd pedestrians (:class:`CrowdMember`) not yet in a crowd by policy and
    crowd id, in obstacle order, and give each group its shared crowd (its class's
    :meth:`~CrowdMember.make_crowd`, from the obstacles' current states and body radii).
    Pedestrians already in a crowd keep it.  Returns the new crowds."""
    groups: dict[tuple[type[CrowdMember], str], list[Obstacle]] = {}
    for ob in obstacles:
        m = ob.motion
        if isinstance(m, CrowdMember) and m.crowd is None:
            groups.setdefault((type(m), m.crowd_id), []).append(ob)
    out: list[Any] = []
    for (kind, _), members in groups.items():
        models = [cast(CrowdMember, ob.motion) for ob in members]
        crowd = kind.make_crowd(
            models,
            np.array([ob.state.position for ob in members], dtype=float),
            np.array([ob.state.velocity for ob in members], dtype=float),
            [float(ob.body.bounding_radius) for ob in members],
        )
        for i, member in enumerate(models):
            member.crowd = crowd
            member.index = i
        out.append(crowd)
    return out


def crowds_seeing_robot(obstacles: Sequence[Obstacle]) -> list[Any]:
    """The crowds of ``obstacles`` (joined; ORCA or social force: any shared ``crowd`` with
    ``sees_robot`` and ``see_robot``) that see the robot, each once, in obstacle order."""
    out: list[Any] = []
    for ob in obstacles:
        crowd = getattr(ob.motion, "crowd", None)
        if getattr(crowd, "sees_robot", False) and not any(c is crowd for c in out):
            out.append(crowd)
    return out
