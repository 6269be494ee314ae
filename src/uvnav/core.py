"""The navigation contract every layer reads: worlds, laws, probes, and the one step loop.

A **world** holds one scene of one vehicle kind (the Ch. 2 unicycle, the Ch. 3 flyer, the Ch. 4
planar UUV, the Ch. 5 UUV with its sonar array) with one or more agents.  It owns the exact
integration, the obstacles' motion, the collision checks, the sensors and the metrics'
bookkeeping.  A **law** (``Law[Obs, Cmd]``) is reset with an agent's limits, goal and generator,
then sees only the observation its world's sensor makes and returns a command.  **Probes**
watch the loop (recorders, traces of a law's internal state) without the loop knowing them.

:func:`run_loop` is the only place where decisions are taken and timed (Gymnasium's ``Env`` and
PettingZoo's ``ParallelEnv`` wrap the same world step by step, so an env episode and
``uvnav simulate`` give the same trajectory)::

    laws reset -> world.start()
    while not world.done:
        for i in world.acting():           # agents whose decision is due now
            obs = world.observe(i)         # sensor of the world (the law's only input)
            cmd = law_i.act(obs)           # timed: thread CPU time and wall time
            world.apply(i, cmd)            # saturated and counted when outside the limits
            probes.on_decision(...)
        probes.on_step(...)                # the state before the step
        world.advance()                    # every dt: vehicles, bodies, clearance, status
    probes.on_end(...)                     # the final state

**Group laws.**  A law whose ``group_key`` is not ``None`` belongs to a group: the laws of one
episode with equal keys are decided together by one :class:`LawGroup` (made by the first member's
``make_group()``), once per decision time, before the other agents: ``group.decide(world,
members, laws)`` returns the members' commands, which are applied and recorded as the others'
are (each member's decision time is the group's CPU and wall time divided equally among the
members deciding; probes get ``obs=None``).  A group may read more of the world than one
agent's observation (e.g. :class:`DiscAgents`, the state of every disc robot), so only laws that
say so join one (``orca-shared-v1``, :mod:`uvnav.controllers.orca_shared`).

**Bulk hold.**  When no probe watches, the world has ``apply_many(agents, commands)`` and the
group ``decide_many(world, members, laws)`` (both optional), the group's commands travel as one
array (a row per member, in the world's layout: ``(V, u)`` for the unicycle), held by one
``apply_many`` call, and the members' decisions are recorded in one pass
(:meth:`AgentLog.record_group`): no command object is made per member.  What is held, counted
and recorded is what the per-member path holds, counts and records.

Decision period and integration step are separate: a world says when a decision is due (every
``control_period``, a whole multiple of ``dt``).  The loop counts each agent's mode switches and
times each decision with :func:`time.thread_time_ns` (CPU time of this thread, immune to other
processes on a loaded machine; wall time is kept beside it).

This module imports nothing from uvnav: it is the bottom layer.
"""

from __future__ import annotations

import functools
import time as _time
from collections.abc import Collection, Hashable, Sequence
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from typing import Any, ClassVar, Protocol, TypeVar, runtime_checkable

import numpy as np

ObsT_co = TypeVar("ObsT_co", covariant=True)
CmdT = TypeVar("CmdT")
ObsT_contra = TypeVar("ObsT_contra", contravariant=True)
CmdT_co = TypeVar("CmdT_co", covariant=True)

#: Vehicle kinds: the Ch. 2 unicycle (also the Ch. 8 multi-robot agents), the Ch. 3/5 3D vehicle,
#: the Ch. 4 planar underwater vehicle (velocity-commanded, box bound, bounded turn) and the
#: holonomic disc robot of the crowd-navigation benchmarks (any 2D scene can hold it).
VEHICLES: tuple[str, ...] = ("unicycle", "vehicle3d", "uuv2d", "holonomic")

#: Observation kinds a world's sensor makes and a law reads: range-limited exact readings of the
#: bodies (Ch. 2/3), the Ch. 4 viewing-cone sonar, the Ch. 5 nine-beam sonar array.
SENSINGS: tuple[str, ...] = ("exact", "sonar-fan", "sonar-array")

#: Episode outcomes (``timeout`` also while an episode runs and at ``t_max``).
STATUSES: tuple[str, ...] = ("success", "collision", "timeout")


@runtime_checkable
class Law(Protocol[ObsT_contra, CmdT_co]):
    """A navigation law: it sees only its observation and returns its vehicle's command.

    ``oracle`` is True when the law reads ground truth it could not sense (the world then hands
    it the true rates instead of estimates); ``mode`` names the law's current mode (``"M1"``...)
    for the mode-switch metric.
    """

    name: ClassVar[str]
    oracle: bool

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None: ...

    def act(self, obs: ObsT_contra) -> CmdT_co: ...

    @property
    def mode(self) -> str: ...


class World(Protocol[ObsT_co, CmdT]):
    """One scene stepped by :func:`run_loop`.

    ``vehicle`` and ``sensing`` (a vehicle kind: :data:`VEHICLES` or a plug-in's; one of
    :data:`SENSINGS`) say which laws can drive it.  ``t`` is the time [s], ``dt`` the
    integration step [s], ``ratio`` the integration steps per decision; ``done`` becomes True
    when every agent has arrived, collided, or ``t_max`` is reached.  The counting rules (steps,
    status, arrival time, sums) are one bookkeeper's, :mod:`uvnav.sim.ledger`.
    """

    t: float
    dt: float
    ratio: int
    done: bool

    @property
    def vehicle(self) -> str: ...

    @property
    def sensing(self) -> str: ...

    @property
    def n_agents(self) -> int: ...

    def law_setup(self, agent: int) -> tuple[Any, np.ndarray, np.random.Generator]:
        """``(spec, goal, rng)`` to reset agent ``agent``'s law with."""
        ...

    def start(self, oracles: Sequence[bool]) -> None:
        """State, clearance and status at t = 0, after the laws' reset; ``oracles[i]`` says
        whether agent i's law reads ground truth."""
        ...

    def acting(self) -> Sequence[int]:
        """Agents whose decision is due now (empty between decisions)."""
        ...

    def observe(self, agent: int = 0) -> ObsT_co: ...

    def apply(self, cmd: CmdT, agent: int = 0) -> CmdT:
        """Hold ``cmd`` from now on (saturated and counted when outside the limits); returns the
        command applied."""
        ...

    def advance(self) -> None:
        """One integration step ``dt``."""
        ...

    def metrics(self, log: AgentLog, agent: int = 0) -> Any:
        """Agent ``agent``'s :class:`~uvnav.sim.metrics.EpisodeMetrics`, from the loop's log."""
        ...

    def close(self) -> None:
        """The episode is over: write back what the scene's objects should hold."""
        ...

    def recorder(self) -> Any:
        """A probe that records the run (the world's own trajectory type from its
        ``finish()``)."""
        ...

    def result(self, logs: Sequence[AgentLog], recorder: Any) -> Any:
        """The episode's result from the loop's logs and the recorder (``None`` unrecorded):
        :class:`~uvnav.sim.setup.EpisodeResult` for one vehicle,
        :class:`~uvnav.sim.setup.MultiResult` for N robots."""
        ...


@runtime_checkable
class LawGroup(Protocol):
    """Decides the members of a group of laws together (module docstring, "Group laws")."""

    def decide(self, world: Any, agents: Sequence[int], laws: Sequence[Any]) -> Sequence[Any]:
        """The commands of ``agents`` (members whose decision is due, in index order), one per
        agent; ``laws`` are all the episode's laws (by agent)."""
        ...


@dataclass(frozen=True)
class DiscAgents:
    """Every agent of a world of disc robots at a decision time, as a group law reads it
    (:meth:`~uvnav.sim.multi.MultiUnicycleWorld.disc_agents`).

    Attributes:
        time: the time now [s].
        positions: (N, 2) centres [m].
        headings: (N,) headings [rad] (the direction of the last velocity).
        velocities: (N, 2) velocities [m/s] (the held commands; zero once an agent is done).
        radii: (N,) body radii [m].
        active: (N,) agents neither arrived nor collided.
        sensing_range: (N,) each agent's sensing range [m].
        exact: (N,) whether each agent senses the others exactly (true velocities, no noise).
    """

    time: float
    positions: np.ndarray
    headings: np.ndarray
    velocities: np.ndarray
    radii: np.ndarray
    active: np.ndarray
    sensing_range: np.ndarray
    exact: np.ndarray


class Probe(Protocol):
    """Watches :func:`run_loop`.  Every hook is optional (see :class:`BaseProbe`)."""

    def on_start(self, world: Any, laws: Sequence[Any]) -> None: ...

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None: ...

    def on_step(self, world: Any, laws: Sequence[Any]) -> None: ...

    def on_end(self, world: Any, laws: Sequence[Any]) -> None: ...


class BaseProbe:
    """A probe that does nothing; subclasses override the hooks they need."""

    def on_start(self, world: Any, laws: Sequence[Any]) -> None:
        """After ``world.start()``."""

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        """After agent ``agent``'s law decided and ``applied`` was applied."""

    def on_step(self, world: Any, laws: Sequence[Any]) -> None:
        """Before each ``world.advance()`` (the state the step starts from)."""

    def on_end(self, world: Any, laws: Sequence[Any]) -> None:
        """After the last step (the final state)."""


@dataclass
class AgentLog:
    """What the loop measured for one agent.

    Attributes:
        mode_switches: changes of the law's reported mode between consecutive decisions.
        decision_us: CPU time of each decision [µs] (:func:`time.thread_time_ns`).
        decision_wall_us: wall time of each decision [µs].
        last_mode: the mode reported at the last decision (``""`` before any).
    """

    mode_switches: int = 0
    decision_us: list[float] = field(default_factory=list)
    decision_wall_us: list[float] = field(default_factory=list)
    last_mode: str = ""
    _decided: bool = False

    @property
    def timed_us(self) -> list[float]:
        """The decisions' CPU times [µs] that the metrics summarise: all but the first when
        there are several (the first carries the warm-up: lazy imports, JIT compilation, caches;
        it stays in :attr:`decision_us`)."""
        return self.decision_us[1:] if len(self.decision_us) > 1 else list(self.decision_us)

    def decision_array(self) -> np.ndarray:
        """:attr:`decision_us` as an array (one zero when no decision was made)."""
        return np.asarray(self.decision_us) if self.decision_us else np.zeros(1)

    @staticmethod
    def record_group(
        logs: Sequence[AgentLog], laws: Sequence[Any], agents: Sequence[int], cpu_ns: int,
        wall_ns: int,
    ) -> None:  # fmt: skip
        """:meth:`record` for each of ``agents`` (``laws[i].mode``, the same CPU and wall time
        each), in one pass."""
        cpu, wall = cpu_ns / 1000.0, wall_ns / 1000.0
        for i in agents:
            log, mode = logs[i], laws[i].mode
            if mode != log.last_mode:
                if log._decided:
                    log.mode_switches += 1
                log.last_mode = mode
            log._decided = True
            log.decision_us.append(cpu)
            log.decision_wall_us.append(wall)

    def record(self, mode: str, cpu_ns: int, wall_ns: int) -> None:
        """Account for one decision."""
        if mode != self.last_mode:
            if self._decided:
                self.mode_switches += 1
            self.last_mode = mode
        self._decided = True
        self.decision_us.append(cpu_ns / 1000.0)
        self.decision_wall_us.append(wall_ns / 1000.0)


def run_loop(
    world: World[Any, Any], laws: Sequence[Law[Any, Any]], probes: Sequence[Probe] = ()
) -> list[AgentLog]:
    """Run ``world`` to its end with ``laws[i]`` driving agent i; returns each agent's log.

    The laws are reset here (with :meth:`World.law_setup`), then the world is started.

    Raises:
        ValueError: the number of laws is not the world's number of agents.
    """
    if len(laws) != world.n_agents:
        raise ValueError(f"{len(laws)} law(s) for a world with {world.n_agents} agent(s)")
    for i, law in enumerate(laws):
        spec, goal, rng = world.law_setup(i)
        law.reset(spec, goal, rng)
    world.start([bool(getattr(law, "oracle", False)) for law in laws])
    logs = [AgentLog() for _ in laws]
    keys: list[Hashable | None] = [getattr(law, "group_key", None) for law in laws]
    groups: dict[Hashable, LawGroup] = {}
    for law, key in zip(laws, keys, strict=True):
        if key is not None and key not in groups:
            groups[key] = law.make_group()  # type: ignore[attr-defined]
    for p in probes:
        p.on_start(world, laws)
    cpu_ns, wall_ns = _time.thread_time_ns, _time.perf_counter_ns
    # the bound methods the loop calls at every step, looked up once
    observe, apply, advance, deciding = world.observe, world.apply, world.advance, world.acting
    acts = [law.act for law in laws]
    records = [log.record for log in logs]
    apply_many = None if probes else getattr(world, "apply_many", None)
    bulk = {k: getattr(g, "decide_many", None) if apply_many else None for k, g in groups.items()}
    whole = len(groups) == 1 and None not in keys  # every agent in the one group
    record_group = AgentLog.record_group
    while not world.done:
        acting = deciding()
        if groups and acting:
            for key, group in groups.items():
                members = acting if whole else [i for i in acting if keys[i] == key]
                if not members:
                    continue
                many = bulk[key]
                if many is not None:  # module docstring, "Bulk hold"
                    c0, w0 = cpu_ns(), wall_ns()
                    held = many(world, members, laws)
                    c1, w1 = cpu_ns(), wall_ns()
                    m = len(members)
                    apply_many(members, held)  # type: ignore[misc]
                    record_group(logs, laws, members, (c1 - c0) // m, (w1 - w0) // m)
                    continue
                c0, w0 = cpu_ns(), wall_ns()
                cmds = group.decide(world, members, laws)
                c1, w1 = cpu_ns(), wall_ns()
                m = len(members)
                for i, cmd in zip(members, cmds, strict=True):
                    applied = apply(cmd, i)
                    records[i](laws[i].mode, (c1 - c0) // m, (w1 - w0) // m)
                    for p in probes:
                        p.on_decision(world, i, laws[i], None, applied)
            acting = [] if whole else [i for i in acting if keys[i] is None]
        for i in acting:
            obs = observe(i)
            act = acts[i]
            c0, w0 = cpu_ns(), wall_ns()
            cmd = act(obs)
            c1, w1 = cpu_ns(), wall_ns()
            applied = apply(cmd, i)
            records[i](laws[i].mode, c1 - c0, w1 - w0)
            for p in probes:
                p.on_decision(world, i, laws[i], obs, applied)
        for p in probes:
            p.on_step(world, laws)
        advance()
    for p in probes:
        p.on_end(world, laws)
    return logs


@functools.cache
def load_plugins(group: str, taken: Collection[str] = (), what: str = "plug-in") -> dict[str, Any]:
    """The objects of the entry points of ``group`` by name (third-party laws' siblings: scene
    generators, motion models, sensors, Chapter 5 locators), loaded once per arguments
    (``taken`` hashable: a tuple or a frozenset; ``load_plugins.cache_clear()`` loads again).

    Raises:
        RuntimeError: a plug-in takes a name in ``taken`` (the built-ins') or another plug-in's.
    """
    found: dict[str, Any] = {}
    for ep in entry_points(group=group):
        if ep.name in taken or ep.name in found:
            raise RuntimeError(f"{what} {ep.name!r} of {ep.value} is already registered")
        found[ep.name] = ep.load()
    return found
