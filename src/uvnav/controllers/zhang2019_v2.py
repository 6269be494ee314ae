"""``zhang2019-v2`` / ``zhang2019-holonomic-v2``: the thesis's forecast-circle tangent law extended
to every body that can reach the robot — a law for crowds.

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 2, §2.3: the forecast circle (2.11), its tangent lines and forecast
vectors (2.12)-(2.13), the sliding-mode heading law (2.15) and the target-approaching mode (2.16).
``zhang2019-v1`` (:mod:`uvnav.controllers.zhang2019`) is that law as the chapter states it and
stays unchanged for the reproduction.

**What it keeps from Chapter 2.**

* The forecast circle: where a boundary point of a body may be one forecast time T_f from now —
  centred at the point, radius ``(||v_i|| + |u_i| R_i) T_f`` grown by the robot's radius and a
  margin (v1's note 2).
* The tangent lines from the robot to the forecast circles as the directions worth steering along
  (2.12)-(2.13); per body the outermost tangent on each side over the forecast circles of all its
  boundary points (v1's note 3), so a non-convex body is passed, not grazed.
* The sliding-mode heading law with its boundary layer, ``u = U_max sat(beta / (U_max T_c))``
  (2.15; v1's note 5), and slowing by cos(beta) while turning (v1's note 7), for the unicycle.
* M1 (2.16): V_max toward T when nothing can reach the robot; the speed lowered near T.

**What it adds, and why.**  Measured on crowds (CrowdNav circle crossing, ETH recordings), v1
fails because it avoids the *one* nearest obstacle (or group) in its way, turns
into the next stream of people, and never slows down, waits or backs off.  v2 therefore

1. takes the tangent directions of *all* forecast circles of bodies that can reach the robot within
   the ``horizon`` H (plus the goal direction, the previous choice and ``n_headings`` evenly spread
   directions, so that a way out exists when every tangent is blocked) — no grouping of
   neighbours is needed, because every candidate is checked against every body;
2. pairs each direction with several speeds (``speed_levels`` x V_max, and standing still) and
   checks every candidate velocity against every predicted body over H: the first time of contact
   of the robot's disc (radius + margin) with each body's boundary discs under constant
   velocities (the bodies' velocities as observed; a rotating body's boundary points move with
   ``v_i + u_i x (q - c_i)``), in closed form;
3. chooses the candidate of least cost ``||v - v_pref|| + w_ttc / t_c`` (v_pref: V_max toward T;
   t_c: the first contact time, infinite when none within H), among the candidates whose first
   contact is later than ``min_ttc`` when there is one — so the robot keeps its speed where that is
   safe, slows down or stops where only that is safe, and backs away (a direction with a negative
   component toward T) where even standing still is not;
4. holds its choice: a small cost ``w_change ||v - v_prev||`` keeps it from switching sides between
   decisions (the role of v1's direction tag).
5. inside the safety margin (the robot already within radius sum + margin of a body) judges a
   closing candidate by when the bodies themselves would touch, not 0 for all of them, so that
   it still tells stepping toward a passing pedestrian from standing still.

**Social comfort** (off by default: ``w_social`` 0). Success says nothing of how the robot treats
people; the intrusion ratio of Liu et al. (ICRA 2023, CrowdNav++; :mod:`uvnav.sim.social`) counts
the steps at which the robot stands where a visible pedestrian will be within the next 1.25 s, i.e.
passing in front of someone walking. The steps above only keep ``comfort`` metres from where each
walking body *is*; with ``w_social`` > 0 a candidate also pays ``w_social soc`` (cost in m/s),
``soc`` [m] the depth of its path into the bodies' forecasts: over the robot's first
``social_horizon`` T_s seconds along the candidate (the turn, then straight, as above), the largest
``reach + social_band - g`` over the moving bodies (clipped at 0), ``g`` the smallest distance from
the robot at time t to the body's constant-velocity forecast from t to t + ``social_forecast`` S
(the segment ``q + w t .. q + w (t + S)``). In the body's frame the forecast seen along a straight
stretch of the path sweeps a parallelogram, so ``g`` is a point-to-parallelogram distance in closed
form (:func:`uvnav.geometry.contact.forecast_gap`). A path that crosses where someone is about to
walk pays up to ``reach + band`` (about 0.7 m for a person); one that passes behind them, or waits,
pays nothing. Bodies standing still have no forecast beyond themselves, nor a ``comfort`` distance
(slower than ``comfort_min_speed``): they are kept clear of only. The term only adds to the cost,
so safety (the first contact, ``min_ttc``) still ranks first, and the branch-and-bound bound stays
a lower bound. On a vehicle with acceleration limits the rolled-out paths' segments that start
before T_s are read the same way (:func:`path_social`); figures: ``docs/design-notes.md``.

**A route around the crowd** (``route_*``): the law steers for a way point, not for T itself: a
fan of routes (:mod:`uvnav.controllers.crowd_route`; on the ideal unicycle searched every 0.75 s,
shorter and costed over the 12 nearest walkers), a grid path with acceleration limits
(:mod:`uvnav.controllers.crowd_grid`).

**Declared noise.** Each body is grown by ``noise_sigmas`` times the centre noise its reading
declares (``position_std``) in the one body table every decision path reads
(:func:`~uvnav.controllers.zhang2019_v2_bodies.body_table`); exact readings declare none.

The holonomic robot takes the chosen velocity as it is; the unicycle steers toward the chosen
direction with the sliding-mode law at the chosen speed times cos(beta).

**Checked along the path.**  The unicycle does not move along the chosen velocity: it turns at
most U_max, slows by cos(beta) while it turns, and steers again at every decision.  Its
candidates are therefore checked along the path its own steering drives toward each of them,
decision after decision over H (the rolled-out paths below, with no limits on the ideal
vehicle).  With ``rollout_paths`` off they are checked as the chapter's geometry suggests: one
turn at U_max along its chord at ``s cos(beta / 2)``, then a straight line at s (the compiled
loop below).  With that check a direction behind the robot costs the same as one ahead, so the
choice jumped between decisions and the robot turned on the spot or zigzagged until a human
reached it (``docs/design-notes.md``, "The unicycle checked along its paths").

**Acceleration limits.** The thesis's unicycle changes its speed and turn rate at once.  On a
unicycle whose spec has limits (``UnicycleSpec.accel_max`` a, ``turn_accel_max`` B: the vehicle
moves its speed and turn rate toward the held command by at most a dt and B dt a step) the thesis
says nothing; the choices made here (:mod:`uvnav.controllers.zhang2019_limits`):

* What the robot knows: its speed from its odometry (``obs.speed``), its turn rate from its
  last command as the vehicle applies it (moved toward it by at most B times the time since),
  nothing of the bodies beyond what it senses.
* The same candidates (directions at the speed levels, v_pref, standing still), each checked
  along the path the vehicle will follow toward it from its current speed and turn rate: the
  law's own steering (below) replayed decision after decision for the horizon H, the vehicle
  ramping between decisions, in substeps of at most ``rollout_step``, on arcs, or, on a
  turn-then-move vehicle, turning by the period's ramped turn at each decision and moving
  straight, as that vehicle does (checked on arcs, its paths were some centimetres off, and
  near people that was the margin: ``docs/design-notes.md``, issue 35); the
  path's segments are checked against every body in closed form, each body's reach grown by
  ``limited_spread`` times the segment's end time (a robot that cannot sidestep at once keeps
  clear of where a body may be once others bend its path; on a vehicle with acceleration
  limits a standing body's by at most ``still_cap``, and the check ends ``goal_horizon`` after
  the goal could be reached: people standing beside the goal would otherwise hold the robot
  off it).  Standing still is braking at a,
  turning toward T as the turn rate allows.
* The command is kept within the dynamic window of one period T (the last one measured):
  speed within v +- a T, turn rate within u +- B T, so that the vehicle reaches it by the next
  decision; the turn is the sliding-mode law slowed to a rate that can still be stopped at the
  aim, ``u^2 / (2 B) + u T / 2 <= |beta|``, so it does not overshoot and orbit.
* A stopping-distance check: after one period at its speed v_T the robot needs
  ``v_T T + v_T^2 / (2 a)`` of path before a contact; a safe candidate must leave that much
  (with the defaults, 1 m/s and 1 m/s^2, the 3 s of ``min_ttc`` already do, so it rarely binds),
  and where no candidate is safe one that leaves it is preferred.
* v_pref is lowered to ``sqrt(2 a d)`` at d from T, so that the robot can stop there.

The unicycle's decision runs, after reading the readings into arrays, in one loop compiled
with numba (:mod:`uvnav.controllers.zhang2019_v2_paths`: the reachable bodies and their discs,
the candidates visited by their cost without the risk terms, each path rolled out only as far
as it is checked, bodies culled by boxes; the numpy building blocks are its reference, and run
where numba is not installed or the social term is on).

Two equal implementations of the holonomic robot's decision (and the unicycle's with
``rollout_paths`` off).  The reference is numpy, vectorised over candidates x boundary discs
(:mod:`uvnav.controllers.zhang2019_v2_bodies`, :func:`choose_velocity`).  With numba (the ``fast``
extra) everything after reading the observation's readings into arrays (:func:`body_table`,
:func:`~uvnav.controllers.zhang2019_v2_loop.outline_rings`) runs in one compiled call
(:func:`uvnav.controllers.zhang2019_v2_loop.plan_loop`, then
:func:`uvnav.geometry.contact.decide_py`): it visits the candidates by a lower bound of their cost
and stops once a safe candidate costs no more than the next bound, picking the reference's
candidate (tests: hypothesis on random scenes); ``benchmarks/bench_zhang2019_v2.py`` times it.
Units: metres, seconds, radians.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from uvnav.controllers.base import (
    ControllerInfo,
    UnicycleController,
    check_params,
    heading_rate_toward,
    register,
)
from uvnav.controllers.crowd_route import CrowdRoute, RouteParams
from uvnav.controllers.holonomic import HolonomicLaw, toward_goal
from uvnav.controllers.zhang2019_limits import (
    BoolArray,
    RampModel,
    path_risk,
    path_social,
    preferred_under_limits,
    rollout,
    stoppable,
)
from uvnav.controllers.zhang2019_v2_bodies import (
    body_table,
    boundary_discs,
    extra_headings,
    reachable,
    tangent_directions,
)
from uvnav.controllers.zhang2019_v2_loop import (
    N_PRM,
    N_WEIGHTS,
    P_HEADINGS,
    P_SPACING,
    P_VMAX,
    outline_rings,
    plan_loop,
)
from uvnav.controllers.zhang2019_v2_paths import M_HORIZON
from uvnav.controllers.zhang2019_v2_paths import _approach as paths_approach
from uvnav.controllers.zhang2019_v2_paths import _turn as paths_turn
from uvnav.controllers.zhang2019_v2_paths import _window as paths_window
from uvnav.controllers.zhang2019_v2_steer import PathConstants, path_constants, plan_on_floats
from uvnav.dynamics.omni import VelocityCommand
from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.contact import (
    TANGENT_SLACK,
    candidate_risk,
    candidate_risk_compiled,
    social_risk,
    social_risk_compiled,
)
from uvnav.geometry.kernels3d import numba_enabled
from uvnav.prediction.tracking import CentreTracker
from uvnav.sensors.observation import Observation, any_estimated

IntArray = np.ndarray


@dataclass(frozen=True)
class Zhang2019V2Params(RouteParams):
    """Parameters of ``zhang2019-v2`` and ``zhang2019-holonomic-v2`` (the ``route_*`` ones:
    :class:`~uvnav.controllers.crowd_route.RouteParams`, on with the unicycle's defaults here).

    Attributes:
        horizon: H [s], how far ahead every candidate is checked against every body.
        forecast_horizon: T_f [s] of the forecast circles (thesis: 1 s).
        safety_margin: clearance [m] kept beyond the robot's radius.
        n_headings: evenly spread extra directions (a way out when every tangent is blocked).
        speed_levels: fractions of V_max tried with every direction (standing still is always
            tried).
        w_ttc: weight [m] of the collision term ``w_ttc / t_c``.
        w_change: weight of ``||v - v_prev||`` (holding the choice between decisions).
        min_ttc: first contact [s] a candidate must clear when any candidate does.
        spacing: largest distance [m] between boundary samples of a polygon body.
        max_tangent_bodies: the nearest bodies whose tangents become candidates (all bodies are
            still checked against every candidate).
        comfort: clearance [m] beyond the margin below which a candidate pays
            ``w_comfort`` [1/s] per metre, by its smallest clearance over ``comfort_horizon`` [s].
        track_estimates: where the bodies' rates are *estimated* (finite differences of sensed
            centres), plan on the centres and velocities of a constant-velocity Kalman filter per
            body (:class:`uvnav.prediction.tracking.CentreTracker`); readings with known rates
            are used as they are.
        track_position_std: the filter's centre noise [m] for readings that declare none.
        track_accel_std: the filter's white-noise acceleration of a body [m/s^2], at least.
        track_turn_std: the filter's turn-rate spread [rad/s] (``CentreTracker.turn_std``).
        rollout_step: longest substep [s] of the rolled-out paths (module docstring,
            "Acceleration limits").
        limited_spread: how fast [m/s] each body's reach grows with the look-ahead time of a
            rolled-out path's check (module docstring, "Acceleration limits"); the holonomic
            robot's decision, and the unicycle's with ``rollout_paths`` off, do not read it.
        rollout_paths: on the unicycle without acceleration limits too, check each candidate
            along the rolled-out path of the law's own steering (module docstring, "Checked
            along the path"); off: the compiled check of one turn, then a straight line.  A
            unicycle with acceleration limits always rolls out.
        w_social: weight [1/s] of the social term (module docstring, "Social comfort"): a
            candidate pays ``w_social`` per metre by which its path over ``social_horizon`` [s]
            comes closer than ``social_band`` [m] beyond the radius sum to where a moving body
            will be over the next ``social_forecast`` [s]; 0 turns the term off.
        comfort_min_speed: only bodies moving at this speed [m/s] or faster are kept
            ``comfort`` away; one standing still is only kept clear of (people standing at or
            beside the target would otherwise hold the robot off it for good).
        noise_sigmas: each body is grown by this many times the centre noise [m] its reading
            declares (``position_std``; :func:`~uvnav.controllers.zhang2019_v2_bodies.body_table`).
        goal_horizon: on a vehicle with acceleration limits, the rolled-out paths are checked
            only until the goal could be reached, ``distance / V_max + goal_horizon`` [s] (at
            most ``horizon``): a person standing behind the goal is no contact; 0: off.
        still_cap: on a vehicle with acceleration limits, a body slower than
            ``comfort_min_speed`` grows along a rolled-out path by ``limited_spread`` times the
            look-ahead up to ``still_cap`` [m] (0: no cap, as a walking one): the spread would
            otherwise keep the robot off a goal beside which people stand.  Both were tuned
            together on the limited unicycle (CrowdNav's circle, 20 humans, cases 0-99: 0.857
            against 0.765 without; held out 0.831 against 0.741, before the turn-then-move
            vehicle's turn was fixed, ``docs/design-notes.md``); on
            the ideal unicycle, which they did not help (the harder crowd 0.960 against 0.970),
            neither is read, nor by the numpy reference
            (:func:`~uvnav.controllers.zhang2019_limits.path_risk`).
    """

    route_weight: float = 3.0
    route_lookahead: float = 3.0
    route_period: float = 0.75
    route_bodies: int = 12
    horizon: float = 4.0
    forecast_horizon: float = 1.0
    safety_margin: float = 0.05
    n_headings: int = 16
    speed_levels: tuple[float, ...] = (1.0, 0.6, 0.3)
    w_ttc: float = 1.0
    w_change: float = 0.1
    min_ttc: float = 3.0
    spacing: float = 0.25
    max_tangent_bodies: int = 12
    comfort: float = 0.3
    comfort_horizon: float = 1.0
    w_comfort: float = 10.0
    track_estimates: bool = True
    track_position_std: float = 0.1
    track_accel_std: float = 0.2
    track_turn_std: float = 0.5
    rollout_step: float = 0.125
    limited_spread: float = 0.1
    rollout_paths: bool = True
    w_social: float = 0.0
    social_horizon: float = 2.0
    social_forecast: float = 1.25
    social_band: float = 0.1
    comfort_min_speed: float = 0.1
    noise_sigmas: float = 0.5
    goal_horizon: float = 1.0
    still_cap: float = 0.05

    def __post_init__(self) -> None:
        super().__post_init__()
        check_params(
            self,
            positive=(
                "horizon",
                "forecast_horizon",
                "spacing",
                "min_ttc",
                "comfort_horizon",
                "track_position_std",
                "track_accel_std",
                "rollout_step",
                "social_horizon",
                "social_forecast",
            ),
            non_negative=(
                "safety_margin",
                "w_ttc",
                "w_change",
                "comfort",
                "w_comfort",
                "limited_spread",
                "w_social",
                "social_band",
                "track_turn_std",
                "comfort_min_speed",
                "noise_sigmas",
                "goal_horizon",
                "still_cap",
            ),
        )
        for name in ("n_headings", "max_tangent_bodies"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 0:
                raise ValueError(f"{name} must be an integer >= 0 (got {value!r})")
        levels = tuple(self.speed_levels)
        if not levels or not all(isinstance(s, int | float) and 0 < s <= 1 for s in levels):
            raise ValueError(
                f"speed_levels must be fractions in (0, 1] (got {self.speed_levels!r})"
            )


# -- pure functions ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Choice:
    """The chosen velocity [m/s] (2,), its first contact time [s] and whether it is the
    preferred one (M1)."""

    velocity: FloatArray
    ttc: float
    preferred: bool


def choose_velocity(
    position: FloatArray,
    v_pref: FloatArray,
    v_prev: FloatArray,
    headings: FloatArray,
    v_max: float,
    discs: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    params: Zhang2019V2Params,
    *,
    heading: float | None = None,
    u_max: float = math.inf,
) -> Choice:
    """The candidate velocity of least cost (module docstring, steps 2-4).

    ``discs``: boundary discs (centres, velocities, radius sums with the robot's disc and margin)
    and the bodies' rows (:func:`boundary_discs` with the bounding reach appended).
    ``headings`` [rad] are the candidate directions, each tried at every speed level.  With
    ``heading`` [rad] given (a unicycle turning at most ``u_max`` [rad/s]) a candidate is checked
    as the robot will drive it: first the turn, ``|beta| / u_max`` seconds along the chord's
    direction ``heading + beta / 2`` at ``s cos(beta / 2)`` (0 for a turn past pi), then straight
    at ``s`` (the turn slowdown of v1's note 7, averaged over the turn).
    """
    p = params
    pref = np.asarray(v_pref, dtype=float)
    ang, spd, cand = candidates(headings, v_max, p.speed_levels, pref)
    turn, tau = cand, np.zeros(len(cand))
    if heading is not None:
        beta = (ang - heading + np.pi) % (2.0 * np.pi) - np.pi
        tau = np.minimum(np.abs(beta) / u_max, p.horizon)
        mid = heading + 0.5 * beta
        s1 = spd * np.maximum(np.cos(0.5 * beta), 0.0)
        turn = s1[:, None] * np.column_stack([np.cos(mid), np.sin(mid)])
    q, w, reach, bodies = discs
    args = (p.horizon, p.comfort, p.comfort_horizon, p.safety_margin, p.comfort_min_speed)
    social = (p.social_horizon, p.social_forecast, p.social_band)
    if numba_enabled():
        ttc, pen = candidate_risk_compiled(position, cand, turn, tau, (q, w, reach), bodies, *args)
        soc = social_risk_compiled(position, cand, turn, tau, (q, w, reach), social)
    else:
        ttc, pen = candidate_risk(position, cand, turn, tau, (q, w, reach), *args)
        soc = social_risk(position, cand, turn, tau, (q, w, reach), social)
    return least_cost(cand, ttc, pen, pref, v_prev, p, soc=soc if p.w_social > 0.0 else None)


def candidates(
    headings: FloatArray, v_max: float, speed_levels: tuple[float, ...], v_pref: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The candidate velocities: every direction of ``headings`` [rad] at every speed level
    (fractions of ``v_max`` [m/s]), then ``v_pref``, then standing still (facing along
    ``v_pref``): their directions [rad] (K,), speeds [m/s] (K,) and velocities (K, 2)."""
    speeds = v_max * np.asarray(speed_levels, dtype=float)
    ang = np.append(np.repeat(headings, len(speeds)), math.atan2(v_pref[1], v_pref[0]))
    spd = np.append(np.tile(speeds, len(headings)), math.hypot(v_pref[0], v_pref[1]))
    ang, spd = np.append(ang, ang[-1]), np.append(spd, 0.0)  # standing still
    cand = spd[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
    return ang, spd, cand


def base_cost(
    cand: FloatArray, v_pref: FloatArray, v_prev: FloatArray, w_change: float
) -> FloatArray:
    """Each candidate's cost without the risk terms, ``||v - v_pref|| + w_change ||v - v_prev||``
    [m/s] (a lower bound of its cost)."""
    return np.asarray(np.hypot(*(cand - v_pref).T) + w_change * np.hypot(*(cand - v_prev).T))


def least_cost(
    cand: FloatArray,
    ttc: FloatArray,
    pen: FloatArray,
    v_pref: FloatArray,
    v_prev: FloatArray,
    params: Zhang2019V2Params,
    *,
    admissible: BoolArray | None = None,
    soc: FloatArray | None = None,
) -> Choice:
    """The candidate of least cost among ``cand`` (ordered as :func:`candidates` makes them),
    given each one's first contact ``ttc`` [s] and comfort penalty ``pen`` [m] (module
    docstring, steps 3-4).  With ``admissible`` (a mask: the robot can still stop before the
    contact), a safe candidate must be admissible too, and where none is safe an admissible
    one is preferred.  ``soc`` [m]: each one's social term (module docstring, "Social comfort"),
    paid at ``w_social`` when given."""
    p = params
    cost = base_cost(cand, v_pref, v_prev, p.w_change)
    cost = cost + p.w_ttc / np.maximum(ttc, 1e-3) + p.w_comfort * pen
    if soc is not None:
        cost = cost + p.w_social * soc
    safe = ttc > p.min_ttc
    if admissible is not None:
        safe = safe & admissible
        if not np.any(safe) and np.any(admissible):
            safe = admissible
    if np.any(safe):
        cost = np.where(safe, cost, np.inf)
    k = int(np.argmin(cost))
    return Choice(cand[k], float(ttc[k]), bool(k == len(cand) - 2 and np.isinf(ttc[k])))


def plan(
    obs: Observation,
    goal: FloatArray,
    v_max: float,
    robot_radius: float,
    period: float,
    v_prev: FloatArray,
    params: Zhang2019V2Params,
    *,
    heading: float | None = None,
    u_max: float = math.inf,
    loop: bool | None = None,
    constants: tuple[FloatArray, FloatArray] | None = None,
) -> Choice:
    """One decision of v2 for a robot at ``obs.position`` (both vehicles).

    ``loop``: decide in one loop (:func:`uvnav.controllers.zhang2019_v2_loop.plan_loop`, which
    ends in :func:`uvnav.geometry.contact.decide_py`, compiled when numba is enabled) or by
    :func:`~uvnav.controllers.zhang2019_v2_bodies.tangent_directions` and
    :func:`choose_velocity` in numpy (the reference); ``None``:
    the loop exactly when numba is enabled.  ``constants``: :func:`loop_constants` of these
    ``params``, ``v_max`` and ``robot_radius`` when the caller keeps them (computed otherwise)."""
    p = params
    use_loop = numba_enabled() if loop is None else loop
    pos = np.asarray(obs.position, dtype=float)
    v_pref = toward_goal(pos, goal, v_max, period)
    if use_loop:
        fixed = constants or loop_constants(p, v_max, robot_radius)
        return _plan_in_loop(obs, v_pref, v_prev, fixed, (heading, u_max), p.noise_sigmas)
    table = body_table(obs.obstacles, p.noise_sigmas)
    keep = reachable(table, v_max, p.horizon)
    if not len(keep):
        return Choice(v_pref, math.inf, True)
    if len(keep) < len(table[0]):
        table = (table[0][keep], table[1][keep], table[2][keep])
    scal = table[0]
    discs_only = bool(np.all(scal[:, 2] > 0.0))  # a crowd: the readings are not read again
    near = () if discs_only else tuple(obs.obstacles[k] for k in keep)
    headings = extra_headings(p.n_headings, v_pref, v_prev)
    pad = robot_radius + p.safety_margin
    q, w, r, owner, rows = boundary_discs(near, p.spacing, table)
    reach = r + pad
    bodies = np.column_stack([rows, bounding_reach(scal, p) + pad])
    tangents = nearest_tangents(pos, (q, w, reach, owner), p)
    return choose_velocity(pos, v_pref, v_prev, np.concatenate([tangents, headings]), v_max,
                           (q, w, reach, bodies), p, heading=heading, u_max=u_max)  # fmt: skip


def loop_constants(
    params: Zhang2019V2Params, v_max: float, robot_radius: float
) -> tuple[FloatArray, FloatArray]:
    """The arguments of :func:`uvnav.controllers.zhang2019_v2_loop.plan_loop` that stay fixed over
    an episode: its ``prm`` vector and its ``speeds`` (not to be written to)."""
    p = params
    prm = np.zeros(N_PRM)
    prm[:N_WEIGHTS] = (p.horizon, p.comfort, p.comfort_horizon, p.w_ttc, p.w_change, p.w_comfort,
                       p.min_ttc, robot_radius + p.safety_margin, p.forecast_horizon,
                       p.max_tangent_bodies, p.safety_margin, p.w_social, p.social_horizon,
                       p.social_forecast, p.social_band, p.comfort_min_speed)  # fmt: skip
    prm[P_SPACING], prm[P_HEADINGS], prm[P_VMAX] = p.spacing, p.n_headings, v_max
    return prm, v_max * np.asarray(p.speed_levels, dtype=float)


def _plan_in_loop(
    obs: Observation,
    v_pref: FloatArray,
    v_prev: FloatArray,
    constants: tuple[FloatArray, FloatArray],
    turning: tuple[float | None, float],
    noise_sigmas: float,
) -> Choice:
    """:func:`plan`'s loop path: the readings read into arrays once, the rest of the decision in
    :func:`uvnav.controllers.zhang2019_v2_loop.plan_loop`."""
    pose, (heading, u_max) = obs.pose, turning
    moving = 1.0 if math.hypot(v_prev[0], v_prev[1]) > 1e-9 else 0.0  # as extra_headings
    state = np.array((pose[0], pose[1], math.nan if heading is None else heading, u_max,
                      v_pref[0], v_pref[1], v_prev[0], v_prev[1], moving), dtype=float)  # fmt: skip
    readings = obs.obstacles
    table = body_table(readings, noise_sigmas)
    prm, speeds = constants
    out = plan_loop(state, table, outline_rings(readings, table[0]), speeds, prm)
    return Choice(out[:2].copy(), float(out[2]), bool(out[3]))


def bounding_reach(scal: FloatArray, params: Zhang2019V2Params) -> FloatArray:
    """Per body (``scal``: :func:`body_table`'s scalars) the radius [m] of a disc about its
    centre, moving with it, that holds its boundary discs over the horizon: a polygon's boundary
    discs reach half a spacing past its bounding disc; a rotating one's move along straight
    lines (v_i + u_i x (q - c_i)), so over H a point at rho from the centre drifts out to
    rho sqrt(1 + (u_i H)^2)."""
    spin = np.sqrt(1.0 + (scal[:, 1] * params.horizon) ** 2)
    return np.asarray(
        np.where(scal[:, 2] > 0.0, scal[:, 3], scal[:, 3] * spin + 0.5 * params.spacing)
    )


def nearest_tangents(
    position: FloatArray,
    discs: tuple[FloatArray, FloatArray, FloatArray, IntArray],
    params: Zhang2019V2Params,
) -> FloatArray:
    """The tangent directions [rad] of the forecast circles of the ``max_tangent_bodies``
    nearest bodies (``discs``: boundary discs' centres, velocities, reaches and owners, nearest
    body first)."""
    q, w, reach, owner = discs
    n_few = int(np.searchsorted(owner, params.max_tangent_bodies))  # readings come nearest first
    grow = reach * (1.0 + TANGENT_SLACK) + np.hypot(w[:, 0], w[:, 1]) * params.forecast_horizon
    return tangent_directions(position, q[:n_few], grow[:n_few], owner[:n_few])


def plan_limited(
    obs: Observation,
    goal: FloatArray,
    model: RampModel,
    robot_radius: float,
    now: tuple[float, float],
    v_prev: FloatArray,
    params: Zhang2019V2Params,
    *,
    loop: bool | None = None,
    constants: tuple[FloatArray, FloatArray] | None = None,
) -> Choice:
    """One decision of v2 on the unicycle checked along rolled-out paths (module docstring,
    "Acceleration limits"): the candidates of :func:`plan`, each checked along the path the
    vehicle follows toward it from its speed and turn rate ``now`` ([m/s], [rad/s]).

    ``loop``: choose in one loop (:func:`uvnav.controllers.zhang2019_v2_paths.plan_paths`,
    compiled when numba is enabled; not with the social term) or by :func:`rollout`,
    :func:`path_risk` and :func:`least_cost` in numpy (the reference); ``None``: the loop exactly
    when numba is enabled; ``constants``: the loop's ``prm`` vector and speeds
    (:class:`PathConstants`) when already made."""
    p = params
    if (numba_enabled() if loop is None else loop) and p.w_social == 0.0:
        out = plan_on_floats(obs, goal, model, now, v_prev, p.noise_sigmas, constants or (
            path_constants(model, p, robot_radius),
            model.v_max * np.asarray(p.speed_levels, dtype=float)))  # fmt: skip
        return Choice(out[:2].copy(), float(out[2]), bool(out[3]))
    pos = np.asarray(obs.position, dtype=float)
    v_pref = preferred_under_limits(pos, goal, model)
    pose = np.asarray(obs.pose, dtype=float)
    table = body_table(obs.obstacles, p.noise_sigmas)
    keep = reachable(table, model.v_max, p.horizon)
    table = (table[0][keep], table[1][keep], table[2][keep])
    near = () if bool(np.all(table[0][:, 2] > 0.0)) else tuple(obs.obstacles[k] for k in keep)
    q, w, r, owner, _ = boundary_discs(near, p.spacing, table)
    reach = r + robot_radius + p.safety_margin
    tangents = nearest_tangents(pos, (q, w, reach, owner), p)
    headings = np.concatenate([tangents, extra_headings(p.n_headings, v_pref, v_prev)])
    ang, spd, cand = candidates(headings, model.v_max, p.speed_levels, v_pref)
    times, xy, speeds = rollout(pose, now[0], now[1], ang, spd, model, p.horizon,
                                p.rollout_step)  # fmt: skip
    ttc, pen = path_risk(times, xy, (q, w, reach), p.horizon, p.comfort, p.comfort_horizon,
                         p.safety_margin, p.limited_spread, p.comfort_min_speed)  # fmt: skip
    brakes = stoppable(times, xy, speeds, ttc, model)
    soc = (
        path_social(times, xy, (q, w, reach), p.social_horizon, p.social_forecast, p.social_band)
        if p.w_social > 0.0
        else None
    )
    return least_cost(cand, ttc, pen, v_pref, v_prev, p, admissible=brakes, soc=soc)


# -- the two laws -----------------------------------------------------------------------------


class LoopConstants:
    """A law's :func:`loop_constants`, kept while its parameters and vehicle spec are the same
    objects."""

    def __init__(self) -> None:
        self._of: tuple[object, object] | None = None
        self._value: tuple[FloatArray, FloatArray] | None = None

    def get(self, params: Zhang2019V2Params, spec: Any) -> tuple[FloatArray, FloatArray]:
        """:func:`loop_constants` of ``params`` and ``spec``'s V_max and radius."""
        of = self._of
        if self._value is None or of is None or of[0] is not params or of[1] is not spec:
            self._of = (params, spec)
            self._value = loop_constants(params, float(spec.v_max), float(spec.radius))
        return self._value


def finite_position(pose: FloatArray) -> bool:
    """The position ``pose[:2]`` is finite (two float checks, no array made)."""
    return math.isfinite(pose[0]) and math.isfinite(pose[1])


def _tracker(p: Zhang2019V2Params) -> CentreTracker | None:
    if not p.track_estimates:
        return None
    return CentreTracker(p.track_position_std, p.track_accel_std, turn_std=p.track_turn_std)


def tracked(obs: Observation, tracker: CentreTracker | None) -> Observation:
    """``obs`` with the tracker's centres and velocities for the bodies whose rates were
    estimated (the same object when nothing was estimated or there is no tracker)."""
    if tracker is None or not any_estimated(obs.obstacles):
        return obs
    pos = np.asarray(obs.position, dtype=float)
    return dataclasses.replace(obs, obstacles=tracker.update(obs.time, obs.obstacles, pos))


@dataclass(frozen=True)
class Zhang2019HolonomicV2Params(Zhang2019V2Params):
    """``zhang2019-holonomic-v2``'s parameters: :class:`Zhang2019V2Params` with the route
    layer's own defaults (:mod:`uvnav.controllers.crowd_route`): searched at every decision over
    every walker."""

    route_weight: float = 2.0
    route_lookahead: float = 4.0
    route_period: float = 0.0
    route_bodies: int = 0


class Zhang2019HolonomicV2(HolonomicLaw):
    """v2 on the holonomic robot: the chosen velocity as it is."""

    name: ClassVar[str] = "zhang2019-holonomic-v2"

    def __init__(self, params: Zhang2019V2Params | None = None) -> None:
        super().__init__()
        self.params = params or Zhang2019HolonomicV2Params()
        self.last_choice: Choice | None = None
        self._tracker = _tracker(self.params)
        self._fixed = LoopConstants()
        self._route = CrowdRoute(self.params, self.params.comfort_min_speed)

    def _reset_law(self, rng: np.random.Generator) -> None:
        self.last_choice = None
        self._tracker = _tracker(self.params)
        self._route.reset()

    def act(self, obs: Observation) -> VelocityCommand:
        period = self.decision_period(obs.time)
        spec = self._spec
        if not finite_position(obs.pose):
            return VelocityCommand(0.0, 0.0)
        obs = tracked(obs, self._tracker)
        goal = self._route.aim(obs.position, self._goal, obs.obstacles, spec.v_max, obs.time)
        choice = plan(obs, goal, spec.v_max, spec.radius, period,
                      self.current_velocity(obs), self.params,
                      constants=self._fixed.get(self.params, self._spec))  # fmt: skip
        self.last_choice = choice
        self._mode = "M1" if choice.preferred else "M2"
        return VelocityCommand(float(choice.velocity[0]), float(choice.velocity[1])).clipped(spec)


class Zhang2019V2(UnicycleController):
    """v2 on the unicycle: sliding-mode turn toward the chosen direction (2.15)."""

    name: ClassVar[str] = "zhang2019-v2"

    def __init__(self, params: Zhang2019V2Params | None = None) -> None:
        super().__init__()
        self.params = params or Zhang2019V2Params()
        self.last_choice: Choice | None = None
        self._aim = np.zeros(2)
        self._tracker = _tracker(self.params)
        self._fixed = LoopConstants()
        self._paths = PathConstants()
        self._route = CrowdRoute(self.params, self.params.comfort_min_speed)

    def _reset_law(self, rng: np.random.Generator) -> None:
        self.last_choice = None
        self._route.reset(limited=not self._spec.ideal, unicycle=True)
        self._aim = np.zeros(2)
        self._tracker = _tracker(self.params)
        self._turn = (0.0, 0.0)  # the turn rate at the last decision and the one commanded

    def act(self, obs: Observation) -> UnicycleCommand:
        period = self.decision_period(obs.time)
        spec = self._spec
        if not (finite_position(obs.pose) and math.isfinite(obs.pose[2])):
            return UnicycleCommand(0.0, 0.0)
        obs = tracked(obs, self._tracker)
        goal = self._route.aim(obs.position, self._goal, obs.obstacles, spec.v_max, obs.time)
        if self.params.rollout_paths or not spec.ideal:
            return self._act_limited(obs, period, goal)
        choice = plan(obs, goal, spec.v_max, spec.radius, period, self._aim, self.params,
                      heading=obs.heading, u_max=spec.u_max,
                      constants=self._fixed.get(self.params, self._spec))  # fmt: skip
        self.last_choice = choice
        self._mode = "M1" if choice.preferred else "M2"
        v = choice.velocity
        speed = float(np.hypot(v[0], v[1]))
        self._aim = np.asarray(v, dtype=float)
        if speed < 1e-9:  # standing still: face the target meanwhile
            gap = goal - obs.position
            aim = math.atan2(float(gap[1]), float(gap[0]))
        else:
            aim = math.atan2(float(v[1]), float(v[0]))
        beta = wrap_scalar(aim - obs.heading)
        speed *= max(math.cos(beta), 0.0)  # v1's turn slowdown (note 7)
        return UnicycleCommand(speed, heading_rate_toward(beta, spec.u_max, period)).clipped(spec)

    def _act_limited(self, obs: Observation, period: float, goal: FloatArray) -> UnicycleCommand:
        """The decision for ``goal`` on a vehicle with acceleration limits (module docstring):
        the speed it has from its odometry, the turn rate it has from its last command as the
        vehicle applies it; a command within the window of one period."""
        spec = self._spec
        model, prm, speeds = self._paths.get(self.params, spec, period)
        if self.params.goal_horizon > 0.0 and not spec.ideal:  # paths checked until the goal
            reach = math.dist(self._goal, obs.position) / spec.v_max + self.params.goal_horizon
            if reach < prm[M_HORIZON]:
                prm = prm.copy()
                prm[M_HORIZON] = reach
        u_before, u_cmd = self._turn
        u_now = paths_approach(u_before, u_cmd, spec.turn_accel_max * period)
        v_now = min(max(float(obs.speed), 0.0), spec.v_max) if math.isfinite(obs.speed) else 0.0
        choice = plan_limited(obs, goal, model, spec.radius, (v_now, u_now), self._aim,
                              self.params, constants=(prm, speeds))  # fmt: skip
        self.last_choice = choice
        self._mode = "M1" if choice.preferred else "M2"
        v = choice.velocity
        speed = float(np.hypot(v[0], v[1]))
        self._aim = np.asarray(v, dtype=float)
        gap = v if speed >= 1e-9 else goal - obs.position  # standing: face the target
        beta = wrap_scalar(math.atan2(float(gap[1]), float(gap[0])) - obs.heading)
        lo, hi = paths_window(v_now, model.accel, period, 0.0, model.v_max)
        v_out = min(max(speed * max(math.cos(beta), 0.0), lo), hi)  # as speed_command
        u_out = paths_turn(beta, u_now, prm)  # as turn_command
        self._turn = (u_now, u_out)
        return UnicycleCommand(v_out, u_out).clipped(spec)


_REFERENCE = "Y. Zhang, thesis Ch. 2, eqs. (2.11)-(2.16), extended to crowds (module docstring)"
register(
    ControllerInfo(
        name="zhang2019-v2",
        factory=Zhang2019V2,
        params_type=Zhang2019V2Params,
        summary="Thesis Ch. 2 tangent law for crowds: forecast-circle tangents of every body, each "
        "candidate checked against all, speed chosen with the heading; plans with the "
        "robot's acceleration limits.",
        reference=_REFERENCE,
        acceleration_limits=True,
    )
)
register(
    ControllerInfo(
        name="zhang2019-holonomic-v2",
        factory=Zhang2019HolonomicV2,
        params_type=Zhang2019HolonomicV2Params,
        summary="zhang2019-v2 on the holonomic robot: the chosen velocity applied as it is, "
        "steering for a route around the crowd.",
        reference=_REFERENCE,
        vehicle="holonomic",
    )
)
