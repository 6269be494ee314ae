"""One episode of any world: :func:`run_episode` builds the world the setup describes, runs the
one loop :func:`uvnav.core.run_loop` over it with the law(s) and the probes, and returns the
world's result.

Every world answers the same questions (:class:`uvnav.core.World`: the loop's, then
``recorder()`` and ``result(logs, recorder)``); which world a setup builds is decided once, by
its type:

========================  ==============================================  =====================
setup                     world                                           result
========================  ==============================================  =====================
``EpisodeSetup``          :class:`~uvnav.sim.episode.World2D` (any planar  ``EpisodeResult``
                          vehicle: unicycle, holonomic, plug-ins)
``Episode3DSetup``        :class:`~uvnav.sim.episode3d.Vehicle3DWorld`     ``EpisodeResult``
``Uuv2dSetup``            :class:`~uvnav.sim.episode_uuv2d.Uuv2dWorld`     ``EpisodeResult``
``UUV3DSetup``            :class:`~uvnav.sim.episode_uuv3d.UUV3DWorld`     ``EpisodeResult``
``MultiSetup``            :class:`~uvnav.sim.multi.MultiUnicycleWorld`, or  ``MultiResult``
                          the compiled :class:`~uvnav.sim.packed_swarm.
                          PackedSwarm` when the swarm packs
========================  ==============================================  =====================
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, overload

import numpy as np

from uvnav.core import Probe, run_loop
from uvnav.dynamics.vehicles import vehicles_2d
from uvnav.geometry.kernels3d import numba_enabled
from uvnav.sim.episode import World2D
from uvnav.sim.episode3d import Episode3DSetup, Trajectory3D, Vehicle3DWorld
from uvnav.sim.episode_uuv2d import Uuv2dSetup, Uuv2dTrajectory, Uuv2dWorld
from uvnav.sim.episode_uuv3d import LocatedTrace, UUV3DSetup, UUV3DWorld
from uvnav.sim.multi import MultiUnicycleWorld
from uvnav.sim.packed_swarm import run_swarm, swarm_check
from uvnav.sim.recorder import Trajectory
from uvnav.sim.setup import EpisodeResult, EpisodeSetup, MultiResult, MultiSetup


def _world_2d(
    setup: EpisodeSetup,
    rng: np.random.Generator,
    record: bool,
    *,
    vehicle: str = "unicycle",
    compiled: bool | None = None,
    swept: bool = True,
) -> World2D:
    if vehicle not in vehicles_2d():
        raise ValueError(f"no 2D world for vehicle {vehicle!r}; known: {', '.join(vehicles_2d())}")
    packed = numba_enabled() if compiled is None else compiled
    return World2D(setup, rng, exact=record, packed=packed, swept=swept, vehicle=vehicle)


def _world_3d(setup: Episode3DSetup, rng: np.random.Generator, record: bool) -> Vehicle3DWorld:
    return Vehicle3DWorld(setup, rng, exact=record)


def _world_uuv2d(
    setup: Uuv2dSetup, rng: np.random.Generator, record: bool, *, swept: bool = True
) -> Uuv2dWorld:
    return Uuv2dWorld(setup, rng, swept=swept)


def _world_uuv3d(setup: UUV3DSetup, rng: np.random.Generator, record: bool) -> UUV3DWorld:
    return UUV3DWorld(setup, rng)


def _world_multi(
    setup: MultiSetup, rng: np.random.Generator, record: bool, *, vectorised: bool = True
) -> MultiUnicycleWorld:
    return MultiUnicycleWorld(setup, rng, vectorised=vectorised)


#: the world each setup type builds (its options are the factory's keywords)
WORLDS: dict[type, Callable[..., Any]] = {
    EpisodeSetup: _world_2d,
    Episode3DSetup: _world_3d,
    Uuv2dSetup: _world_uuv2d,
    UUV3DSetup: _world_uuv3d,
    MultiSetup: _world_multi,
}


@overload
def run_episode(
    setup: EpisodeSetup, law: Any, rng: np.random.Generator, *, record: bool = ...,
    probes: Sequence[Probe] = ..., **options: Any,
) -> EpisodeResult[Trajectory]: ...  # fmt: skip
@overload
def run_episode(
    setup: Episode3DSetup, law: Any, rng: np.random.Generator, *, record: bool = ...,
    probes: Sequence[Probe] = ..., **options: Any,
) -> EpisodeResult[Trajectory3D]: ...  # fmt: skip
@overload
def run_episode(
    setup: Uuv2dSetup, law: Any, rng: np.random.Generator, *, record: bool = ...,
    probes: Sequence[Probe] = ..., **options: Any,
) -> EpisodeResult[Uuv2dTrajectory]: ...  # fmt: skip
@overload
def run_episode(
    setup: UUV3DSetup, law: Any, rng: np.random.Generator, *, record: bool = ...,
    probes: Sequence[Probe] = ..., **options: Any,
) -> EpisodeResult[LocatedTrace]: ...  # fmt: skip
@overload
def run_episode(
    setup: MultiSetup, law: None, rng: np.random.Generator, *, record: bool = ...,
    probes: Sequence[Probe] = ..., **options: Any,
) -> MultiResult: ...  # fmt: skip
def run_episode(
    setup: Any,
    law: Any,
    rng: np.random.Generator,
    *,
    record: bool = True,
    probes: Sequence[Probe] = (),
    **options: Any,
) -> Any:
    """Run one episode to its end (every agent arrived or collided, or ``t_max``).

    Args:
        setup: the instantiated scene (a setup type of :data:`WORLDS`); its bodies' states (and
            their motion models' internal state) are left as they are at the end.
        law: the vehicle's law, reset here; ``None`` for a :class:`MultiSetup`, whose robots
            carry their own.
        rng: the episode generator; the world hands independent children to the law(s) and the
            sensors.
        record: keep the world's record of the run (figures; off for large campaigns).
        probes: more probes to run in the loop (a swarm that would run compiled runs in the
            loop world when there are any: the same result).
        options: the world's own options: 2D ``vehicle`` (the law's vehicle, a name of
            :func:`~uvnav.dynamics.vehicles.vehicles_2d`; ``unicycle``), ``compiled`` (move and
            measure the bodies in compiled calls where the scene allows it, the same numbers;
            default: when numba is enabled) and ``swept`` (judge collisions and the minimum
            clearance along every step, the default; ``False`` judges the end of each step);
            Ch. 4 ``swept``; multi-robot ``vectorised`` (all robots checked and sensed at
            once, and a swarm of ``orca-shared-v1`` robots run compiled: the same results,
            decision times apart; ``False`` forces one field query per robot).

    Raises:
        TypeError: a setup no world is built from, or an option its world does not take.
        ValueError: the world refuses the setup (a control period that is not a whole multiple
            of ``dt``, a ``t_max`` that is not, an unknown vehicle, no robot).
    """
    factory = WORLDS.get(type(setup))
    if factory is None:
        known = ", ".join(t.__name__ for t in WORLDS)
        raise TypeError(f"no world is built from a {type(setup).__name__}; known: {known}")
    if isinstance(setup, MultiSetup):
        if law is not None:
            raise TypeError("a multi-robot setup's robots carry their laws; pass law=None")
        if options.get("vectorised", True) and not probes and swarm_check(setup) is None:
            return run_swarm(setup, rng, record=record)
        laws = [r.controller for r in setup.robots]
    else:
        laws = [law]
    world = factory(setup, rng, record, **options)
    rec = world.recorder() if record else None
    try:
        logs = run_loop(world, laws, [*probes, *([rec] if rec is not None else [])])
    finally:
        world.close()
    return world.result(logs, rec)
