"""Closed-loop evaluation of a driving policy (thesis Chapter 6 "tested on the Udacity platform").

The thesis reports that the trained network "could drive safely without any collisions"; we
measure it.  Per episode on a held-out track: CarRacing's return (1000/N per tile − 0.1 per frame),
tiles reached [%], laps completed, mean |distance to the centreline| [m], off-track events, and
NVIDIA's autonomy score (Bojarski et al. 2016, §7.2): ``1 − interventions · 6 s / elapsed time``,
an intervention being the car more than one track half-width off the centreline, after which the
car is put back on the centreline at rest (:meth:`DrivingSim.put_back`) and driving continues.

Throttle: the policy's own (learned) throttle, or a PI speed controller in its place, as in
Udacity's ``drive.py`` (:class:`PISpeedController`, :func:`with_pi_throttle`), or the expert's own
proportional law tracking a speed the policy chooses (:func:`speed_law_throttle`: the
"learned-speed" throttle, whose network predicts the expert's target speed — a function of the
road ahead, visible in one image — instead of the pedal, which also depends on the speed and is
saturated most of the time; measured: a direct throttle head enters sharp corners at 46–52 m/s
where the expert brakes to about 32 m/s).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from uvnav.driving.expert import ExpertParams
from uvnav.driving.sim import FPS, DrivingSim, Telemetry

#: ``policy(frame, telemetry) -> (steer, throttle)``; a learned policy reads only the frame and
#: the speed (what the car's camera and speedometer give), the expert reads the pose (oracle)
Policy = Callable[[NDArray[np.uint8], Telemetry], tuple[float, float]]
#: seconds charged per intervention by NVIDIA's autonomy score
INTERVENTION_S = 6.0

EPISODE_METRICS = (
    "return",
    "tiles_pct",
    "laps",
    "mean_centre_distance",
    "off_track_events",
    "interventions",
    "autonomy",
    "steps",
    "mean_speed",
)


@dataclass(frozen=True)
class EpisodeResult:
    """Closed-loop metrics of one episode (names as :data:`EPISODE_METRICS`)."""

    seed: int
    ret: float
    tiles_pct: float
    laps: int
    mean_centre_distance: float
    off_track_events: int
    interventions: int
    autonomy: float
    steps: int
    mean_speed: float

    def to_dict(self) -> dict[str, Any]:
        """Plain dict with ``return`` for :attr:`ret`."""
        d = asdict(self)
        d["return"] = d.pop("ret")
        return d


def autonomy_score(interventions: int, elapsed_s: float) -> float:
    """NVIDIA's autonomy: ``1 − interventions · 6 s / elapsed`` (clipped at 0)."""
    if elapsed_s <= 0:
        return 0.0
    return float(max(0.0, 1.0 - interventions * INTERVENTION_S / elapsed_s))


class PISpeedController:
    """PI speed controller (Udacity ``drive.py``'s SimplePIController), throttle in [-1, 1].

    Args:
        set_speed: target speed [m/s].
        kp: proportional gain [1/(m/s)].
        ki: integral gain [1/(m/s·s)].
    """

    def __init__(self, set_speed: float = 35.0, kp: float = 0.1, ki: float = 0.02) -> None:
        self.set_speed = set_speed
        self.kp = kp
        self.ki = ki
        self.integral = 0.0

    def reset(self) -> None:
        """Clear the integral."""
        self.integral = 0.0

    def __call__(self, speed: float, dt: float = 1.0 / FPS) -> float:
        """Throttle for the measured ``speed`` [m/s]."""
        e = self.set_speed - speed
        self.integral = float(np.clip(self.integral + e * dt, -50.0, 50.0))
        return float(np.clip(self.kp * e + self.ki * self.integral, -1.0, 1.0))


def speed_law_throttle(target_speed: float, speed: float, k: float | None = None) -> float:
    """The expert's speed law: ``clip(k (target_speed − speed), −1, 1)``.

    Args:
        target_speed: the speed to drive at [m/s] (the expert's profile, or a network's guess).
        speed: measured speed [m/s].
        k: gain [1/(m/s)] (default: the expert's ``ExpertParams.k_speed``, 0.15).

    Returns:
        Throttle in [-1, 1] (negative = brake).
    """
    gain = ExpertParams().k_speed if k is None else k
    return float(np.clip(gain * (target_speed - speed), -1.0, 1.0))


def with_pi_throttle(policy: Policy, pi: PISpeedController) -> Policy:
    """The policy's steering with the PI controller's throttle."""

    def act(frame: NDArray[np.uint8], tel: Telemetry) -> tuple[float, float]:
        steer, _ = policy(frame, tel)
        return steer, pi(tel.speed)

    return act


def run_closed_loop(
    sim: DrivingSim,
    policy: Policy,
    seed: int,
    *,
    max_steps: int | None = None,
    on_reset: Callable[[], None] | None = None,
) -> EpisodeResult:
    """Drive one episode with interventions and measure it.

    Args:
        sim: simulator (its camera gives the policy's frames).
        policy: ``(frame, telemetry) -> (steer, throttle)``.
        seed: track seed.
        max_steps: step limit (default: the simulator's).
        on_reset: called after reset (e.g. to clear a PI integral).

    Returns:
        The episode's metrics.
    """
    frame, tel = sim.reset(seed)
    if on_reset is not None:
        on_reset()
    limit = max_steps or sim.max_steps
    ret = 0.0
    dist: list[float] = []
    speeds: list[float] = []
    interventions = 0
    steps = 0
    for _ in range(limit):
        steer, throttle = policy(frame, tel)
        st = sim.step_on_track(steer, throttle)
        steps += 1
        ret += st.reward
        frame, tel = st.frame, st.telemetry
        seen = tel if st.left is None else st.left  # the reading before a put-back
        dist.append(abs(seen.centre_distance))
        speeds.append(seen.speed)
        interventions += st.left is not None
        if st.terminated or st.truncated:
            break
    lap = tel.lap_complete or tel.tiles_visited >= tel.n_tiles
    return EpisodeResult(
        seed=seed,
        ret=float(ret),
        tiles_pct=100.0 * tel.tiles_visited / tel.n_tiles,
        laps=int(lap),
        mean_centre_distance=float(np.mean(dist)) if dist else 0.0,
        off_track_events=interventions,
        interventions=interventions,
        autonomy=autonomy_score(interventions, steps / FPS),
        steps=steps,
        mean_speed=float(np.mean(speeds)) if speeds else 0.0,
    )


def summarize(results: list[EpisodeResult]) -> dict[str, float]:
    """Means over episodes of every metric (``return`` etc.) and the episode count ``n``."""
    out: dict[str, float] = {"n": float(len(results))}
    for name in EPISODE_METRICS:
        vals = [r.to_dict()[name] for r in results]
        out[name] = float(np.mean(vals)) if vals else float("nan")
    return out


def expert_policy(sim: DrivingSim, **params: Any) -> Policy:
    """ORACLE: the pure-pursuit expert as a policy (rebuilt for each track on first use)."""
    from uvnav.driving.expert import ExpertParams, PurePursuitExpert

    state: dict[str, Any] = {}
    ep = ExpertParams(**params)

    def act(frame: NDArray[np.uint8], tel: Telemetry) -> tuple[float, float]:
        if state.get("geom") is not sim.geometry:
            assert sim.geometry is not None
            state["geom"] = sim.geometry
            state["expert"] = PurePursuitExpert(sim.geometry, ep)
        expert: PurePursuitExpert = state["expert"]
        return expert.act(tel)

    return act
