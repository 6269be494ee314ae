"""One episode of any scene kind with any compatible law: the one path behind ``uvnav simulate``
(and the API): law/scene compatibility and the law's assumptions are checked here, once.

A law fits a scene when it drives the scene's vehicle and reads the observation the scene's
sensor makes (:class:`~uvnav.scenarios.catalog.SceneKind`'s ``vehicle`` and ``sensing`` against
the registry's :class:`~uvnav.controllers.ControllerInfo`); otherwise :class:`LawMismatchError`
says so in one line.  A law that declares obstacles slower than the robot (thesis (2.6)) is
refused on a 2D scene that breaks it (:func:`uvnav.scenarios.validate_for_controller`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from uvnav.controllers.base import (
    ControllerInfo,
    ControllerParamsError,
    controller_info,
    make_law,
)
from uvnav.scenarios.catalog import Resolved
from uvnav.scenarios.errors import ScenarioError
from uvnav.sim.metrics import METRIC_NAMES


class LawMismatchError(ScenarioError):
    """The law cannot drive the scene (another vehicle or another sensor)."""


class AssumptionError(ScenarioError):
    """The scene breaks an assumption the law declares (thesis (2.6)): the law is refused."""


@dataclass
class Outcome:
    """One episode's result in a kind-independent form.

    Attributes:
        kind: the scene kind; scene: its name; law: the law's name; params: its parameters;
        seed: the episode seed.
        status: ``success``/``collision``/``timeout`` (multi-robot: ``success`` when every
            robot arrived, ``collision`` when any collided, else ``timeout``).
        metrics: the :data:`METRIC_NAMES` of the episode (multi-robot: of the group: success
            = all arrived, collision = any, the others the robots' mean).
        extra: the kind's own results (forbidden regions, inner space, group metrics, robots;
            a single robot's ``contact_time``: the first contact of a collision [s], ``None``
            without one).
        facts: what a campaign stores beside the law's parameters (its ``effective_params``):
            the world's flags (Ch. 4 ``entered_forbidden``, Ch. 5 ``entered_inner_space``) and,
            on a sonar scene (``uuv2d``, ``uuv3d``), ``n_obstacles``; multi-robot: ``group``
            (the group metrics) and ``n_robots``.
        result, setup: the simulator's own result and setup (for figures).
    """

    kind: str
    scene: str
    law: str
    params: dict[str, Any]
    seed: int
    status: str
    metrics: dict[str, Any]
    extra: dict[str, Any] = field(default_factory=dict)
    facts: dict[str, Any] = field(default_factory=dict)
    result: Any = None
    setup: Any = None
    trajectory: Any = None


def default_law(resolved: Resolved) -> tuple[str, dict[str, Any]]:
    """The scene's own law and parameters: its controller section's ``params``, and any other
    setting the section has besides ``name`` (Chapter 5's ``locator``) as the parameter of that
    name."""
    ctrl = resolved.scenario.controller
    settings = ctrl.model_dump(exclude={"name", "params"})
    return str(ctrl.name), {**settings, **dict(getattr(ctrl, "params", {}) or {})}


def check_law(
    resolved: Resolved,
    law: str,
    *,
    assumptions: bool = True,
    params: dict[str, Any] | None = None,
) -> ControllerInfo:
    """The registry entry of ``law`` if it fits ``resolved``'s scene (and, with
    ``assumptions``, if the scene keeps the assumptions the law, with ``params``, declares).

    Raises:
        UnknownControllerError: no such law.
        LawMismatchError: the law drives another vehicle or reads another sensor.
        AssumptionError: the scene breaks an assumption the law declares (thesis (2.6)).
    """
    info = controller_info(law)
    kind = resolved.kind
    if not kind.fits(info):
        raise LawMismatchError(
            resolved.spec,
            "controller",
            f"{law} drives a {info.vehicle} with {info.sensing} sensing; this {kind.name} scene "
            f"has {kind.describe()} (see 'uvnav controllers list --vehicle {kind.vehicle}')",
        )
    if assumptions and kind.name == "nav2d":
        from uvnav.scenarios.build import validate_for_controller

        try:
            validate_for_controller(resolved.scenario, law, params)
        except ScenarioError as exc:
            raise AssumptionError(exc.source, exc.path, exc.problem) from None
    return info


def limits_note(resolved: Resolved, law: str) -> str | None:
    """One line telling that ``law`` does not plan with the acceleration limits its vehicle has
    in the scene (its commands are what the robot aims at, not what it does), or ``None``: no
    limits that its vehicle keeps (the holonomic robot has none), or a law that plans with them
    (``ControllerInfo.acceleration_limits``)."""
    from uvnav.dynamics.vehicles import make_vehicle, vehicles_2d

    robot: Any = getattr(resolved.scenario, "robot", None)
    limits = {name: getattr(robot, name, None) for name in ("accel_max", "turn_accel_max")}
    given = {k: v for k, v in limits.items() if v is not None}
    info = controller_info(law)
    if robot is None or not given or info.acceleration_limits:
        return None
    if info.vehicle not in vehicles_2d():
        return None
    if getattr(make_vehicle(info.vehicle, robot.to_spec()).spec, "ideal", True):
        return None  # its vehicle keeps no acceleration limit
    said = ", ".join(f"{k} {v:g}" for k, v in given.items())
    return (
        f"note: {law} does not plan with the robot's acceleration limits ({said}); the robot "
        "lags its commands"
    )


def episode_seed(resolved: Resolved, seed: int | None) -> int:
    """The episode seed: the generator's number for ``generator:seed``, else ``seed`` (0).

    Raises:
        ScenarioError: another ``seed`` is given with a ``generator:seed`` spec.
    """
    if resolved.seed is not None:
        if seed is not None and seed != resolved.seed:
            raise ScenarioError(
                resolved.spec,
                "seed",
                f"is {resolved.seed} for this generator spec; run "
                f"'{resolved.spec.partition(':')[0]}:{seed}' for seed {seed}",
            )
        return resolved.seed
    return 0 if seed is None else int(seed)


def run_scene(
    resolved: Resolved,
    law: str | None = None,
    params: dict[str, Any] | None = None,
    seed: int | None = None,
    *,
    record: bool = False,
    use_scene_params: bool = True,
    beyond_assumptions: bool = False,
    probes: Sequence[Any] = (),
) -> Outcome:
    """Run one episode of ``resolved`` with ``law`` (default: the scene's own, with its
    parameters unless ``use_scene_params`` is false; ``params`` override them, and are the only
    ones for another law).  ``beyond_assumptions`` runs a law on a scene that breaks an
    assumption it declares (a deliberate experiment; never the default).  ``probes``
    (:class:`uvnav.core.Probe`) watch the run.

    Raises:
        UnknownControllerError, ControllerParamsError, LawMismatchError, AssumptionError: as
            above; ScenarioError: a seed that contradicts a ``generator:seed`` spec.
    """
    own, own_params = default_law(resolved)
    name = law or own
    merged = dict(own_params) if name == own and use_scene_params else {}
    merged.update(params or {})
    check_law(resolved, name, assumptions=not beyond_assumptions, params=merged)
    s = episode_seed(resolved, seed)
    runner = _RUNNERS[resolved.kind.name]
    try:
        return runner(resolved, name, merged, s, record, probes)
    except ControllerParamsError as exc:
        if str(exc).startswith(f"controller {name}"):
            raise
        raise ControllerParamsError(f"controller {name}: {exc}") from None


def _single(
    resolved: Resolved, name: str, params: dict[str, Any], seed: int, res: Any, **kw: Any
) -> Outcome:
    return Outcome(
        kind=resolved.kind.name,
        scene=resolved.name,
        law=name,
        params=params,
        seed=seed,
        status=res.status,
        metrics=res.metrics.to_dict(),
        extra={"contact_time": res.contact_time},
        result=res,
        **kw,
    )


def _setup(r: Resolved, seed: int) -> Any:
    """The setup of ``r``'s scene for episode ``seed`` (what :func:`~uvnav.sim.run.run_episode`
    builds the kind's world from)."""
    kind = r.kind.name
    if kind == "nav2d":
        from uvnav.scenarios.build import build_episode

        return build_episode(r.scenario, seed)
    if kind == "nav3d":
        return r.scenario.build(seed)
    if kind == "uuv2d":
        return r.scenario.to_setup()
    from uvnav.scenarios.ch5 import build_uuv3d

    return build_uuv3d(r.scenario)


def _one_vehicle(
    r: Resolved,
    name: str,
    params: dict[str, Any],
    seed: int,
    record: bool,
    probes: Sequence[Any] = (),
) -> Outcome:
    """One episode of a single-vehicle kind; the world's flags go into ``extra``."""
    from uvnav.sim.run import run_episode

    setup = _setup(r, seed)
    law = make_law(name, **params)
    # a 2D scene holds every planar vehicle: the law's picks the world's
    options: dict[str, Any] = {}
    if r.kind.name == "nav2d":
        options["vehicle"] = controller_info(name).vehicle
    res = run_episode(setup, law, r.kind.episode_rng(seed), record=record, probes=probes, **options)
    out = _single(r, name, params, seed, res, setup=setup, trajectory=res.trajectory)
    out.extra.update(res.flags)
    out.facts.update(res.flags)
    if r.kind.name in ("uuv2d", "uuv3d"):
        out.facts["n_obstacles"] = len(r.scenario.obstacles)
    if r.kind.name == "uuv3d":
        out.extra["locator"] = str(getattr(law.params, "locator", ""))
    return out


def _mean(values: list[Any]) -> float | None:
    nums = [float(v) for v in values if v is not None]
    return sum(nums) / len(nums) if nums else None


def _multi(
    r: Resolved,
    name: str,
    params: dict[str, Any],
    seed: int,
    record: bool,
    probes: Sequence[Any] = (),
) -> Outcome:
    from uvnav.scenarios.multi import build_multi
    from uvnav.sim.run import run_episode

    own, own_params = default_law(r)
    if name == own and params == own_params:  # each robot keeps its own law, if it has one
        setup = build_multi(r.scenario, seed)
    else:
        setup = build_multi(r.scenario, seed, controller=name, params=params)
    res = run_episode(setup, None, r.kind.episode_rng(seed), record=record, probes=probes)
    robots = [m.to_dict() for m in res.robots]
    g = res.group
    status = (
        "success"
        if g.all_arrived
        else ("collision" if any(s == "collision" for s in res.statuses) else "timeout")
    )
    metrics: dict[str, Any] = {key: _mean([row[key] for row in robots]) for key in METRIC_NAMES[2:]}
    metrics["success"] = bool(g.all_arrived)
    metrics["collision"] = status == "collision"
    clear = [row["min_clearance"] for row in robots if row["min_clearance"] is not None]
    metrics["min_clearance"] = min(clear) if clear else None
    for key in ("limit_violations", "mode_switches"):
        metrics[key] = int(sum(row[key] for row in robots))
    metrics["decision_us_p99"] = max(row["decision_us_p99"] for row in robots)
    metrics = {k: metrics[k] for k in METRIC_NAMES}
    names = [rb.name for rb in setup.robots]
    extra = {
        "group": g.to_dict(),
        "robots": [
            {"name": n, "status": s, **row}
            for n, s, row in zip(names, res.statuses, robots, strict=True)
        ],
    }
    return Outcome(
        kind=r.kind.name, scene=r.name, law=name, params=params, seed=seed, status=status,
        metrics=metrics, extra=extra, result=res, setup=setup,
        facts={"group": g.to_dict(), "n_robots": len(setup.robots)},
    )  # fmt: skip


_RUNNERS = {
    "nav2d": _one_vehicle,
    "nav3d": _one_vehicle,
    "uuv2d": _one_vehicle,
    "uuv3d": _one_vehicle,
    "multi2d": _multi,
}
