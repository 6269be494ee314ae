"""Demonstration recording in the Udacity layout (thesis Chapter 6 §6.3, Fig. 6.1).

The expert (:class:`uvnav.driving.expert.PurePursuitExpert`) drives CarRacing tracks; while
recording, correlated steering noise is applied (DART) but the recorded label is the clean expert
command at the state the car is in (steering, throttle, the expert's target speed as an 8th
column and, with the front camera, the exact labels of the left and right images as the 9th and
10th, see :mod:`uvnav.driving.dataset`).  Every ``record_every`` steps the three forward images
(left, centre, right) are written with the labels.  Resumable: each finished episode's seed is
appended to ``episodes.txt``; a rerun skips those seeds (a killed run loses at most the episode
in flight, whose rows are written but not listed — they are kept, as a Udacity recording would be).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.driving.dataset import DatasetError, LogWriter
from uvnav.driving.expert import ExpertParams, PurePursuitExpert, ar1_noise
from uvnav.driving.sim import DrivingSim, Telemetry

DONE_NAME = "episodes.txt"
#: what the dataset's images are (camera, size, field of view, recording noise): read by training
#: and evaluation
META_NAME = "dataset.json"
#: the front camera's field of view [deg] of datasets whose ``dataset.json`` does not say
LEGACY_FOV_DEG = 90.0


@dataclass(frozen=True)
class CollectParams:
    """Recording parameters.

    Attributes:
        record_every: record one row every this many simulator steps (50 Hz).
        noise_sigma: standard deviation of the applied steering noise (normalised steering).
        noise_rho: step-to-step correlation of the noise (0.97 ≈ 0.7 s time constant).
        max_steps: steps per episode (the episode also ends when the lap is done).
    """

    record_every: int = 4
    noise_sigma: float = 0.25
    noise_rho: float = 0.97
    max_steps: int = 1200


def recording_meta(sim: DrivingSim, params: CollectParams) -> dict[str, Any]:
    """What :func:`collect` records with ``sim`` and ``params`` (the ``dataset.json`` fields)."""
    info: dict[str, Any] = {
        "camera": sim.camera,
        "height": sim.frame_shape[0],
        "width": sim.frame_shape[1],
    }
    if sim.camera == "front":
        info["side_shift"] = sim.side_shift
        info["fov_deg"] = round(float(np.degrees(sim.camera_spec.fov)), 6)
    info["noise_sigma"], info["noise_rho"] = params.noise_sigma, params.noise_rho
    return info


def dataset_meta(root: Path | str) -> dict[str, Any]:
    """A dataset folder's ``dataset.json`` (``{}`` when there is none, e.g. a Udacity recording).

    A field written later does not constrain older folders, except the front camera's field of
    view: it was :data:`LEGACY_FOV_DEG` until it was written, and is filled in as such.

    Raises:
        DatasetError: the file is not a JSON object, or a number in it is NaN or ±inf (one line
            naming the file and the field).
    """
    f = Path(root) / META_NAME
    if not f.is_file():
        return {}
    try:
        meta: dict[str, Any] = json.loads(f.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise DatasetError(f"{f}: not valid JSON ({type(exc).__name__})") from None
    if not isinstance(meta, dict):
        raise DatasetError(f"{f}: expected a JSON object, got {type(meta).__name__}")
    for name, value in meta.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise DatasetError(f"{f}: field '{name}': {value} is not a finite number")
    if meta.get("camera") == "front":
        meta.setdefault("fov_deg", LEGACY_FOV_DEG)
    return meta


def meta_conflict(recorded: dict[str, Any], new: dict[str, Any]) -> str | None:
    """The first field a folder was recorded with differently (one line), or ``None``."""
    for name in ("camera", "fov_deg", "noise_sigma", "noise_rho"):
        if name in recorded and name in new and recorded[name] != new[name]:
            return (
                f"field '{name}': dataset was recorded with {recorded[name]!r}, not {new[name]!r}"
            )
    return None


def done_seeds(root: Path | str) -> set[int]:
    """Seeds of the episodes already recorded in a dataset folder."""
    f = Path(root) / DONE_NAME
    if not f.is_file():
        return set()
    return {int(x) for x in f.read_text().split()}


def write_expert_row(
    writer: LogWriter,
    name: str,
    sim: DrivingSim,
    expert: PurePursuitExpert,
    tel: Telemetry,
    label: tuple[float, float, float],
) -> None:
    """Write one dataset row ``name``: the three camera images of now (the front camera's side
    views; the top-down view, which has no side cameras, three times) and the expert's ``label``
    for ``tel`` (:meth:`PurePursuitExpert.label`: steering, throttle, target speed [m/s]), with
    the brake, the speed [m/s] and the side cameras' steering."""
    steer, throttle, v_target = label
    sides: tuple[float, float] | None = None
    if sim.camera == "front":
        left, centre, right = sim.side_views()
        sides = expert.side_steering(tel, sim.side_shift)
    else:
        left = centre = right = sim.topdown_view()
    writer.write(
        name,
        (centre, left, right),
        steering=steer,
        throttle=throttle,
        brake=max(-throttle, 0.0),
        speed=tel.speed,
        target_speed=v_target,
        side_steering=sides,
    )


def collect_episode(
    sim: DrivingSim,
    writer: LogWriter,
    seed: int,
    *,
    params: CollectParams | None = None,
    expert_params: ExpertParams | None = None,
) -> int:
    """Record one expert episode on track ``seed``.

    Args:
        sim: simulator (its front camera geometry and side shift are used).
        writer: dataset writer.
        seed: track seed (also seeds the noise).
        params: recording parameters.
        expert_params: expert parameters.

    Returns:
        The number of rows written.
    """
    p = params or CollectParams()
    rng = np.random.default_rng([seed, 6])
    noise = ar1_noise(rng, p.max_steps, sigma=p.noise_sigma, rho=p.noise_rho)
    _, tel = sim.reset(seed)
    assert sim.geometry is not None
    expert = PurePursuitExpert(sim.geometry, expert_params)
    rows = 0
    for k in range(p.max_steps):
        steer, throttle, v_target = expert.label(tel)
        if k % p.record_every == 0:
            write_expert_row(
                writer, f"{seed:05d}_{k:05d}", sim, expert, tel, (steer, throttle, v_target)
            )
            rows += 1
        st = sim.step_on_track(steer + noise[k], throttle)
        tel = st.telemetry
        if st.terminated or st.truncated:
            break
    writer.flush()
    return rows


def collect(
    root: Path | str,
    seeds: Iterable[int],
    *,
    params: CollectParams | None = None,
    expert_params: ExpertParams | None = None,
    sim: DrivingSim | None = None,
    on_episode: Callable[[int, int], None] | None = None,
) -> int:
    """Record expert episodes into a Udacity-layout folder, skipping seeds already recorded.

    Args:
        root: dataset folder (created).
        seeds: track seeds.
        params: recording parameters.
        expert_params: expert parameters.
        sim: simulator to use (default: front camera 66×200).
        on_episode: called with ``(seed, rows)`` after each episode (progress bars).

    Returns:
        Rows written by this call.
    """
    root = Path(root)
    p = params or CollectParams()
    root.mkdir(parents=True, exist_ok=True)
    done = done_seeds(root)
    own = sim is None
    sim = sim or DrivingSim(max_steps=p.max_steps)
    meta = root / META_NAME
    info = recording_meta(sim, p)
    if meta.is_file():
        conflict = meta_conflict(dataset_meta(root), info)
        if conflict:
            raise ValueError(f"{meta}: {conflict} (record into another folder)")
    else:
        meta.write_text(json.dumps(info))
    writer = LogWriter(root)
    total = 0
    try:
        for seed in seeds:
            if seed in done:
                if on_episode:
                    on_episode(seed, 0)
                continue
            n = collect_episode(sim, writer, seed, params=p, expert_params=expert_params)
            with (root / DONE_NAME).open("a") as fh:
                fh.write(f"{seed}\n")
            total += n
            if on_episode:
                on_episode(seed, n)
    finally:
        writer.close()
        if own:
            sim.close()
    return total
