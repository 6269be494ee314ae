"""Contacts and clearance judged along each integration step of a 2D world (continuous collision
detection), with the kernels of :mod:`uvnav.geometry.sweep` and their motion model: within a step
the robot's centre moves on its chord (a unicycle's arc stays within its ``slack`` of it), each
body's centre and heading move linearly.  Exact for bodies that do not rotate, conservative by
at most 1 mm (twice :data:`ROT_TOL`) below the true gap for those that do.

A world samples its clearance at the end of each step; between two samples a fast robot or body
can pass through another.  :class:`SweptClearance` watches the steps without sweeping most of
them.  With g0 and g1 lower bounds of the sampled gaps at the step's start and end and D the most
any robot point and body point can approach each other over the step (the robot's travel plus
the largest body displacement ``|c1 - c0| + R_b |dh|``), the gap at s is at least ``g0 - s D``
and ``g1 - (1 - s) D``, so the step's closest approach is at least ``(g0 + g1 - D) / 2``:

* a step whose bound is below 0 may hold a contact: it is swept now (bodies culled by the exact
  sweep of their bounding discs), which gives the collision and the fraction of the step at the
  first contact;
* a step whose bound is below the best minimum seen so far may hold the episode's closest
  approach: it is kept (its poses: a few array references, or copies of the bodies' poses from
  which they are made if it is swept), and the kept steps are swept in
  batches and at the end, in increasing order of bound, until the bound reaches the best;
* any other step cannot matter to either.

So the episode's minimum clearance is the minimum along every step, and a contact between two
samples is a collision.  A body that appears (or vanishes) within a step is taken as still at
its pose of the step's end (start).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.polygons import polygon_nearest
from uvnav.geometry.sweep import body_sweep, disc_sweep
from uvnav.obstacles.obstacle import FieldTemplate
from uvnav.sim.social import APPEARED, GapHistory, blame, robot_closed

#: the kernels' tolerance for a rotating body [m]: a gap is at most twice it below the true one
ROT_TOL = 5e-4


class StepPoses(NamedTuple):
    """The bodies and the robot at the start (0) and the end (1) of one step.

    Attributes:
        c0, c1: (k, 2) body centres [m]; h0, h1: (k,) headings [rad];
        present0, present1: (k,) bool, or ``None`` when every body exists;
        p0, p1: (2,) robot centre [m]; slack: the robot path's largest distance from its chord
        [m] (:func:`uvnav.geometry.sweep.arc_slack`).
    """

    c0: FloatArray
    h0: FloatArray
    c1: FloatArray
    h1: FloatArray
    present0: np.ndarray | None
    present1: np.ndarray | None
    p0: FloatArray
    p1: FloatArray
    slack: float


def _made(poses: StepPoses | Callable[[], StepPoses]) -> StepPoses:
    """``poses``, made when it is the function making them."""
    return poses() if callable(poses) else poses


class SweptClearance:
    """The closest approach along every step of one robot (module docstring).

    Args:
        template: the bodies' packed geometry (the world's field template).
        robot_radius: the robot's disc radius [m].
    """

    #: sweep the kept steps once there are this many
    BATCH = 64

    def __init__(self, template: FieldTemplate, robot_radius: float) -> None:
        self.template = template
        self.radius = float(robot_radius)
        self.best = math.inf  # the least swept gap so far [m]
        #: the last step's first contact: its poses, the body, the fraction of the step
        self.contact: tuple[StepPoses, int, float] | None = None
        #: the kept steps: their bound [m] and poses, or the function of copies making them
        self._kept: list[tuple[float, StepPoses | Callable[[], StepPoses]]] = []
        self._empty = not len(template)
        self._ceiling = math.inf
        self._rings = [
            template.rings[:, row, : int(template.counts[row]) + 1].T.copy()
            for row in range(len(template.poly_ids))
        ]

    def step(
        self,
        poses: StepPoses | Callable[[], StepPoses],
        travel: float,
        g0: float,
        g1: float,
        ceiling: float,
        shift: float | None = None,
        later: bool = False,
    ) -> float:
        """Account for one step; returns the fraction of the step [0, 1] at the robot's first
        contact with a body, or NaN when it touched none.

        Args:
            poses: the step's start and end, or a function making them (called only when the
                step must be swept or kept).
            travel: the robot's path length over the step [m].
            g0, g1: lower bounds of the sampled gaps at the step's start and end [m].
            ceiling: an upper bound of the episode's sampled minimum clearance so far [m].
            shift: the most any body point moved over the step [m], when the caller knows it
                (every body present at both ends); else it is measured on ``poses``.
            later: ``poses`` is a function of copies of the step's poses, which may be called
                after the bodies moved on: a kept step keeps it and makes the poses only if it
                is swept (most kept steps are not).
        """
        self._ceiling = min(self._ceiling, ceiling)
        self.contact = None
        if self._empty:
            return math.nan
        made = None if callable(poses) else poses
        if shift is None:
            made = _made(poses)
            c0, c1, h0, h1 = _moving(made)
            spin = np.abs(np.remainder(h1 - h0 + np.pi, 2.0 * np.pi) - np.pi)
            shift = float((np.hypot(*(c1 - c0).T) + spin * self.template.bounding_radii).max())
        reach = travel + shift
        bound = 0.5 * (g0 + g1 - reach)
        if made is not None and (made.present0 is not None or made.present1 is not None):
            bound = min(bound, _changed_bound(made, g0, g1, reach))
        if bound < 0.0:  # a contact is possible: now
            gap, s_hit = self._sweep(_made(poses) if made is None else made, collide=True)
            self.best = min(self.best, gap)
            return s_hit
        if bound < min(self.best, self._ceiling):
            if made is None and not later:
                made = _made(poses)
            self._kept.append((bound, poses if made is None else made))
            if len(self._kept) >= self.BATCH:
                self._flush()
        return math.nan

    def idle(self, bound: float, ceiling: float) -> bool:
        """Whether a step whose closest approach is at least ``bound`` [m] can be left alone
        (neither a contact nor a new minimum), noting ``ceiling`` as :meth:`step` does: the
        shortcut of a caller that knows the step's shift without making its poses."""
        self._ceiling = min(self._ceiling, ceiling)
        return bound >= 0.0 and bound >= min(self.best, self._ceiling)

    def finish(self, sampled_min: float) -> float:
        """The episode's minimum clearance along every step [m], given the exact minimum of the
        sampled gaps ``sampled_min`` (``inf`` without any)."""
        self._ceiling = min(self._ceiling, sampled_min)
        self._flush()
        return min(self.best, sampled_min)

    def _flush(self) -> None:
        for bound, poses in sorted(self._kept, key=lambda e: e[0]):
            if bound >= min(self.best, self._ceiling):
                break
            gap, _ = self._sweep(_made(poses), collide=False)
            self.best = min(self.best, gap)
        self._kept.clear()

    def _sweep(self, poses: StepPoses, *, collide: bool) -> tuple[float, float]:
        """The least gap along the step [m] and, with ``collide``, the fraction at the first
        contact (NaN: none): the bodies whose bounding disc can come below the threshold (0 for
        a contact, else the best minimum), each by its exact kernel."""
        tpl, r = self.template, self.radius + poses.slack
        c0, c1, h0, h1 = _moving(poses)
        p0, p1 = poses.p0, poses.p1
        low, _, _ = disc_sweep(p0, p1, c0, c1, tpl.bounding_radii + r)
        if poses.present0 is not None or poses.present1 is not None:
            low = np.where(_present(poses), low, np.inf)
        threshold = max(min(self.best, self._ceiling), 0.0)
        gap, s_hit = math.inf, math.nan
        for j in np.flatnonzero(low < threshold)[np.argsort(low[low < threshold])].tolist():
            if low[j] >= max(min(gap, threshold), 0.0):
                break  # nothing later is nearer, nor touches
            if tpl.radii[j] > 0:
                g, _, hit = (float(a[0]) for a in disc_sweep(
                    p0, p1, c0[j : j + 1], c1[j : j + 1], tpl.radii[j] + r
                ))  # fmt: skip
            else:
                dh = math.remainder(float(h1[j] - h0[j]), 2.0 * math.pi)
                ring = self._rings[int(tpl.poly_row[j])]
                g, _, hit = body_sweep(
                    p0, p1, c0[j], c1[j], float(h0[j]), dh, ring, r, rot_tol=ROT_TOL
                )
            gap = min(gap, g)
            if collide and g < 0.0 and (math.isnan(s_hit) or hit < s_hit):
                s_hit = hit
                self.contact = (poses, j, hit)
        return gap, s_hit

    def contact_by(
        self,
        dt: float,
        robot_velocity: tuple[float, float],
        pedestrians: np.ndarray,
        history: GapHistory | None = None,
    ) -> str | None:
        """Who closed the gap at the last step's first contact (``None``: it had none): with a
        disc, over the ``history`` that ends with this step (:class:`~uvnav.sim.social.
        GapHistory`); with a polygon (or no history), at that instant
        (:func:`uvnav.sim.social.robot_closed`): the robot's centre and the body's pose there
        under the sweep's motion model, the body's velocity over the step of ``dt`` [s], the
        robot's ``robot_velocity`` [m/s].  A body absent at the step's start appeared in
        contact (``"appeared"``)."""
        if self.contact is None:
            return None
        poses, j, s = self.contact
        tpl = self.template
        p = poses.p0 + s * (poses.p1 - poses.p0)
        c0, c1, h0, h1 = _moving(poses)
        c = c0[j] + s * (c1[j] - c0[j])
        dh = math.remainder(float(h1[j] - h0[j]), 2.0 * math.pi)
        disc = bool(tpl.radii[j] > 0)
        touch, inside = (float(c[0]), float(c[1])), False
        if not disc:
            ring = self._rings[int(tpl.poly_row[j])][:-1]
            h = float(h0[j]) + s * dh
            rot = np.array([[math.cos(h), -math.sin(h)], [math.sin(h), math.cos(h)]])
            _, near, inside = polygon_nearest(p, ring @ rot.T + c)
            touch = (float(near[0]), float(near[1]))
        if poses.present0 is not None and not bool(poses.present0[j]):
            return APPEARED  # the body appeared in contact within the step
        if disc and history is not None:
            return blame(history.robot_closed(j), j, pedestrians)
        velocity = ((c1[j] - c0[j]) / dt).tolist()
        robot = robot_closed(
            (float(p[0]), float(p[1])), (float(c[0]), float(c[1])), touch, disc, inside,
            robot_velocity, (velocity[0], velocity[1]), dh / dt,
        )  # fmt: skip
        return blame(robot, j, pedestrians)


def _changed_bound(poses: StepPoses, g0: float, g1: float, reach: float) -> float:
    """The step's bound where bodies appear or vanish within it: a body sampled only at the end
    (start) is at least ``g1 - reach`` (``g0 - reach``) away along the step."""
    k = len(poses.c0)
    a = np.ones(k, dtype=bool) if poses.present0 is None else poses.present0
    b = np.ones(k, dtype=bool) if poses.present1 is None else poses.present1
    out = math.inf
    if bool((~a & b).any()):
        out = g1 - reach
    if bool((a & ~b).any()):
        out = min(out, g0 - reach)
    return out


def _present(poses: StepPoses) -> np.ndarray:
    """(k,) the bodies present at the step's start or end."""
    k = len(poses.c0)
    a = np.ones(k, dtype=bool) if poses.present0 is None else poses.present0
    b = np.ones(k, dtype=bool) if poses.present1 is None else poses.present1
    return a | b


def _moving(poses: StepPoses) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Start and end centres and headings, a body that appears (vanishes) within the step held
    at its end (start) pose."""
    c0, c1, h0, h1 = poses.c0, poses.c1, poses.h0, poses.h1
    a, b = poses.present0, poses.present1
    if a is None and b is None:
        return c0, c1, h0, h1
    k = len(c0)
    a = np.ones(k, dtype=bool) if a is None else a
    b = np.ones(k, dtype=bool) if b is None else b
    appeared, vanished = ~a & b, a & ~b
    c0 = np.where(appeared[:, None], c1, c0)
    h0 = np.where(appeared, h1, h0)
    c1 = np.where(vanished[:, None], c0, c1)
    h1 = np.where(vanished, h0, h1)
    return c0, c1, h0, h1


#: a contact shallower than this [m] may be missed by :func:`first_contact`
ADVANCE_TOL = 1e-4
#: most exact gaps :func:`first_contact` evaluates in one step
ADVANCE_SAMPLES = 256


def first_contact(
    gap_at: Callable[[float], float],
    g0: float,
    g1: float,
    reach: float,
    *,
    tol: float = ADVANCE_TOL,
    max_samples: int = ADVANCE_SAMPLES,
) -> tuple[float, float]:
    """The first contact within one step by conservative advancement (Mirtich), for worlds whose
    gap has no closed-form sweep (deforming outlines, meshes): ``(s_hit, least gap sampled)``,
    ``s_hit`` the fraction of the step [0, 1] of the first sample found in contact, NaN when none.

    ``gap_at(s)`` is the exact gap [m] at fraction ``s`` of the step and changes by at most
    ``reach`` [m] over the whole step (the robot's travel plus the fastest boundary point's);
    ``g0``, ``g1`` are lower bounds of it at the step's ends (the world's samples).  A step whose
    bound ``(g0 + g1 - reach) / 2`` is at least 0 cannot hold a contact and costs nothing.
    Otherwise the ends are evaluated by ``gap_at`` (so the result does not depend on how good
    the bounds were), and from a sample of gap g the next is ``g / reach`` later: the gap cannot
    reach 0 between two samples, so no contact deeper than ``tol`` is missed (a gap below
    ``tol`` advances by ``tol``), and a contact reported is one (an exact sample below 0), at
    most ``tol / reach`` of the step after the true first contact.  After ``max_samples``
    samples (a graze along the whole step) the step is judged by its end.

    >>> round(first_contact(lambda s: abs(1.0 - 2.0 * s) - 0.2, 0.8, 0.8, 2.0)[0], 3)
    0.4
    >>> first_contact(lambda s: 1.0, 1.0, 1.0, 0.5)
    (nan, inf)
    """
    if not reach > 0.0 or 0.5 * (g0 + g1 - reach) >= 0.0:
        return math.nan, math.inf
    g, g1 = gap_at(0.0), gap_at(1.0)
    least = min(g, g1)
    if g < 0.0:
        return 0.0, least
    s = 0.0
    for _ in range(max_samples):
        s += max(g, tol) / reach
        if s >= 1.0:
            break
        g = gap_at(s)
        least = min(least, g)
        if g < 0.0:
            return s, least
    return (1.0 if g1 < 0.0 else math.nan), least
