"""The Chapter 5 world: a 3D vehicle with the nine-sonar array among shape-changing obstacles.

Thesis Chapter 5 (Y. Zhang and J. Zhang, ICCAE 2022): vehicle (5.1)-(5.7), sonar array (5.8),
obstacles with fixed centres whose surfaces deform (§5.2.4).  :class:`UUV3DWorld` is stepped by
the one loop :func:`uvnav.core.run_loop`, with the 2D world's conventions
(:mod:`uvnav.sim.episode`): the law is asked every ``control_period`` [s] (a whole multiple of
``dt``), vehicle and obstacles advance every ``dt`` [s] with the command held (the vehicle's exact
sphere integration, :func:`~uvnav.dynamics.vehicle3d.vehicle3d_advance`), a command outside the
limits is saturated *and* counted in ``limit_violations``, and the clearance is exact at every
step's end against the obstacles' tessellations at that time (hull sphere against triangle
meshes, exact for the mesh; the mesh is within ``tessellation_error`` of the analytic surface).
Collisions are judged along the whole step by conservative advancement
(:func:`~uvnav.sim.swept.first_contact`: the vehicle's arc is exact at any fraction of the step,
the surfaces are functions of time and no surface point moves faster than its body's
``boundary_speed``), so a contact between two samples deeper than 0.1 mm is a collision.
Metrics carry the names of :data:`uvnav.sim.metrics.METRIC_NAMES`.

Scene 2's check that the vehicle never enters an obstacle's inner space is reported separately
(the result's ``flags["entered_inner_space"]``), as is the located-point error when recorded
(:class:`LocatedTraceProbe`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from uvnav.controllers.zhang_uuv3d import SonarObservation3D
from uvnav.core import AgentLog, BaseProbe
from uvnav.dynamics.vehicle3d import Vehicle3DCommand, Vehicle3DSpec, vehicle3d_advance
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.mesh3d import nearest_on_mesh
from uvnav.obstacles.deforming3d import CompoundBody
from uvnav.sensors.sonar_array import SonarArray, merge_triangles, sonar_scan
from uvnav.sim.ledger import Clock, Ledger, OneVehicle
from uvnav.sim.metrics import EpisodeMetrics
from uvnav.sim.swept import first_contact


@dataclass(frozen=True)
class UUV3DSetup:
    """Everything an episode needs.

    Attributes:
        start: A [m], (3,); heading: initial unit heading, (3,); goal: B [m], (3,).
        spec: vehicle limits and hull radius.
        obstacles: the shape-changing obstacles (stars enter as one-part compounds).
        array: the sonar array (its noise/dropout options apply).
        dt: integration step [s]; control_period: decision period [s]; t_max: time limit [s].
        goal_tolerance: distance to B that counts as arrival [m].
    """

    start: FloatArray
    heading: FloatArray
    goal: FloatArray
    spec: Vehicle3DSpec
    obstacles: tuple[CompoundBody, ...]
    array: SonarArray
    dt: float = 0.05
    control_period: float = 0.2
    t_max: float = 90.0
    goal_tolerance: float = 0.5


@dataclass
class LocatedTrace:
    """The Ch. 5 run at each decision and at the end.

    Attributes:
        times [s], positions [m], modes: the vehicle and the law's mode.
        located: the law's located point [m] (NaN when it located nothing).
        true_nearest: the true nearest obstacle point [m] (NaN where unknown).
    """

    times: list[float] = field(default_factory=list)
    positions: list[FloatArray] = field(default_factory=list)
    modes: list[str] = field(default_factory=list)
    located: list[FloatArray] = field(default_factory=list)
    true_nearest: list[FloatArray] = field(default_factory=list)


def _nearest(
    position: FloatArray, obstacles: Sequence[CompoundBody], t: float, bound: float
) -> tuple[float, FloatArray | None]:
    """Distance [m] from ``position`` to the nearest obstacle surface (tessellations at ``t``) and
    that point; obstacles whose bounding sphere is farther than ``bound`` are skipped."""
    best, point = math.inf, None
    for ob in obstacles:
        for part in ob.parts:
            if float(np.linalg.norm(position - part.centre)) - part.bounding_radius > min(
                best, bound
            ):
                continue
            q, d, _ = nearest_on_mesh(position, part.triangles(t))
            if d < best:
                best, point = d, q
    return best, point


class UUV3DWorld(OneVehicle):
    """The Chapter-5 world: one 3D UUV, its sonar array, deforming obstacles
    (:class:`uvnav.core.World`).

    Every integration step ends with the checks (clearance to the nearest mesh point, inner
    space, arrival; the status and sums are the one :class:`~uvnav.sim.ledger.Ledger`'s):
    :meth:`start` makes them at t = 0, :meth:`advance` integrates one ``dt`` and makes them at the
    new time.  The episode ends on collision, arrival or at ``t_max``.

    Random streams: unlike the other worlds, one generator serves both the law and the sonar:
    :meth:`law_setup` returns ``rng`` itself (not a child), so the law's reset draws and each
    :func:`~uvnav.sensors.sonar_array.sonar_scan` draw from the same stream, in the order the
    chapter's original loop used them (the recorded numbers depend on it; do not split it).

    Args:
        setup: the episode (not modified: the obstacles' surfaces are functions of time).
        rng: the episode generator, shared by the law and the sonar (above).
    """

    vehicle: ClassVar[str] = "vehicle3d"
    sensing: ClassVar[str] = "sonar-array"

    def __init__(self, setup: UUV3DSetup, rng: np.random.Generator) -> None:
        self.setup = setup
        self.rng = rng
        self.spec = setup.spec
        self.clock = Clock(setup.dt, setup.control_period, setup.t_max)
        self.dt, self.ratio = self.clock.dt, self.clock.ratio
        self.goal = np.asarray(setup.goal, dtype=float)
        self.pos = np.asarray(setup.start, dtype=float).copy()
        head = np.asarray(setup.heading, dtype=float)
        self.head = head / np.linalg.norm(head)
        self.obstacles = setup.obstacles
        self._body_speed = max((ob.boundary_speed for ob in self.obstacles), default=0.0)
        self.t = 0.0
        self.done = False

    def law_setup(self, agent: int = 0) -> tuple[Vehicle3DSpec, FloatArray, np.random.Generator]:
        """The law's limits, goal and generator (the world's own ``rng``: class docstring)."""
        return self.spec, self.goal, self.rng

    def start(self, oracles: Sequence[bool] = (False,)) -> None:
        """Bookkeeping and the checks at t = 0; an oracle law gets the true nearest point."""
        self.oracle = bool(oracles[0])
        self.v_held = 0.0
        self.u_held = np.zeros(3)
        self.v_prev = 0.0
        self.inner = False
        self.book = Ledger(self.setup.goal_tolerance)
        gd = self._measure()
        self.done = self.book.begin(self.clearance, gd) or self.clock.up

    def _measure(self) -> float:
        """Clearance, nearest point and inner space at ``t``; returns the distance to B [m]."""
        pos, t = self.pos, self.t
        if self.obstacles:
            d, self.nearest = _nearest(pos, self.obstacles, t, math.inf)
        else:
            d, self.nearest = math.inf, None
        self.clearance = d - self.spec.radius
        if not self.inner and any(bool(ob.in_inner_space(pos[None])[0]) for ob in self.obstacles):
            self.inner = True
        return float(np.linalg.norm(self.goal - pos))

    def observe(self, agent: int = 0) -> SonarObservation3D:
        """The nine-sonar scan of the tessellations now (noise and dropout from ``rng``); the
        true nearest point only for an oracle law."""
        t = self.t
        tri = merge_triangles([p.triangles(t) for ob in self.obstacles for p in ob.parts])
        scan = sonar_scan(self.setup.array, self.pos, self.head, tri, self.rng)
        q = self.nearest
        return SonarObservation3D(
            time=t,
            position=self.pos.copy(),
            heading=self.head.copy(),
            speed=self.v_held,
            goal=self.goal,
            ranges=scan.ranges,
            echo=scan.echo,
            array=self.setup.array,
            truth_point=None if (q is None or not self.oracle) else q.copy(),
        )

    def apply(self, cmd: Vehicle3DCommand, agent: int = 0) -> Vehicle3DCommand:
        """Hold ``cmd``: counted in ``limit_violations`` when outside the limits (judged against
        the current heading, as the turn rate must be normal to it), saturated."""
        if cmd.violates(self.spec, self.head):
            self.book.violations += 1
        cmd = cmd.clipped(self.spec, self.head)
        self.v_held, self.u_held = float(cmd.v), np.asarray(cmd.u, dtype=float)
        return cmd

    def advance(self) -> None:
        """One step ``dt``: effort, the vehicle (exact), then the checks at the new time."""
        dt, book = self.dt, self.book
        book.effort += float(self.u_held @ self.u_held) * dt
        if self.clock.due:
            # Ch. 5's speed term differs from the other worlds' on purpose (the recorded Ch. 5
            # numbers use it): it is counted at every decision, the first included (from rest,
            # v = 0), as ((v - v_prev) / period)^2 * period.
            period = self.setup.control_period
            book.effort += ((self.v_held - self.v_prev) / period) ** 2 * period
            self.v_prev = self.v_held
        start, head, v, u = self.pos, self.head, self.v_held, self.u_held
        t0, g0 = self.t, self.clearance
        new_pos, self.head, self.u_held = vehicle3d_advance(start, head, v, u, dt)
        book.path += float(np.linalg.norm(new_pos - start))
        self.pos = new_pos
        self.t = self.clock.tick()
        gd = self._measure()
        contact_at = None
        if self.obstacles:

            def gap_at(s: float) -> float:
                p = vehicle3d_advance(start, head, v, u, s * dt)[0]
                return _nearest(p, self.obstacles, t0 + s * dt, math.inf)[0] - self.spec.radius

            reach = (abs(v) + self._body_speed) * dt
            s_hit, least = first_contact(gap_at, g0, self.clearance, reach)
            book.min_clear = min(book.min_clear, least)
            if not math.isnan(s_hit):
                contact_at = t0 + s_hit * dt
        self.done = book.judge(self.t, self.clearance, gd, contact_at) or self.clock.up

    def close(self) -> None:
        """Nothing to write back (the obstacles' surfaces are functions of time)."""

    def metrics(self, log: AgentLog, agent: int = 0) -> EpisodeMetrics:
        """The episode's metrics (:mod:`uvnav.sim.metrics`)."""
        return self.book.metrics(log, top_speed=self.spec.v_max)

    def recorder(self) -> LocatedTraceProbe:
        """The probe that records this world's trace."""
        return LocatedTraceProbe()

    def flags(self) -> dict[str, bool]:
        """``entered_inner_space``: the vehicle centre was ever inside an obstacle's
        inner-space box."""
        return {"entered_inner_space": bool(self.inner)}


class LocatedTraceProbe(BaseProbe):
    """Records a :class:`UUV3DWorld` at each decision and at the end: time, position, the law's
    mode, the law's located point and the true nearest obstacle point.

    The located point is a trace of the law's internal state (``law.last_located`` of
    :class:`~uvnav.controllers.zhang_uuv3d.ZhangUUV3D`, NaN when it located nothing), read here
    so that neither the world nor the loop knows it.
    """

    def __init__(self) -> None:
        self.trace = LocatedTrace()

    def _add(self, world: Any, mode: str, located: FloatArray, nearest: FloatArray) -> None:
        tr = self.trace
        tr.times.append(world.t)
        tr.positions.append(world.pos.copy())
        tr.modes.append(mode)
        tr.located.append(located)
        tr.true_nearest.append(nearest)

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        loc = getattr(law, "last_located", None)
        q = world.nearest
        self._add(world, law.mode, loc.point.copy() if loc is not None else np.full(3, np.nan),
                  q.copy() if q is not None else np.full(3, np.nan))  # fmt: skip

    def on_end(self, world: Any, laws: Sequence[Any]) -> None:
        self._add(world, laws[0].mode, np.full(3, np.nan), np.full(3, np.nan))

    def finish(self) -> LocatedTrace:
        return self.trace
