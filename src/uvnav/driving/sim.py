"""The Chapter 6 driving simulator: CarRacing-v3 physics and tracks with two cameras.

The thesis trained and drove in the Udacity simulator (Unity; cannot be installed here).  The
well-kept simulator that can is Gymnasium's ``CarRacing-v3`` (O. Klimov; Box2D physics, random
closed tracks, headless with ``SDL_VIDEODRIVER=dummy``).  :class:`DrivingSim` keeps its physics,
tracks, reward and termination and adds:

* a forward-looking perspective camera rendered from the car pose over the track polygons
  (:mod:`uvnav.driving.camera`), 66×200 (PilotNet's input) or 160×320 (Udacity's frame), also
  shifted left and right so that centre/left/right images exist as on the Udacity car (Fig. 6.1);
  the built-in 96×96 top-down view stays available (``camera="topdown"``);
* telemetry: speed, signed distance to the centreline, heading error, tiles visited;
* ``put_back()``: an intervention that puts the car back on the centreline (NVIDIA's autonomy
  score counts these).

Conventions: ``steer`` ∈ [-1, 1] is normalised to CarRacing's front-wheel limit of 0.4 rad
(+ turns right, as CarRacing and Udacity), ``throttle`` ∈ [-1, 1] is gas when positive and brake
(0.8 × |throttle|, CarRacing's advice) when negative, as Udacity's throttle.
Units are CarRacing's Box2D units, written [m] and [m/s] here.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from uvnav.driving.camera import (
    KERB_RED,
    KERB_WHITE,
    ROAD_A,
    ROAD_B,
    CameraSpec,
    GroundRays,
    TrackRaster,
    ground_rays,
    rasterize_track,
    render_view,
)
from uvnav.driving.track import TrackGeometry, project, track_geometry
from uvnav.geometry.angles import wrap_to_pi

Camera = Literal["front", "topdown"]
#: CarRacing's front-wheel joint limit [rad]: steer = ±1 asks for it
MAX_WHEEL_ANGLE = 0.4
#: CarRacing's frame rate [Hz]
FPS = 50
#: CarRacing's track half-width [m] (TRACK_WIDTH = 40 / SCALE)
HALF_WIDTH = 40 / 6.0


def _gym() -> Any:
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    try:
        import gymnasium
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "uvnav.driving.sim needs gymnasium[box2d]: pip install 'uvnav[envs]'"
        ) from exc
    return gymnasium


@dataclass(frozen=True)
class Telemetry:
    """What the car's instruments and the track map say after a step.

    Attributes:
        step: steps since reset.
        x: position x [m].
        y: position y [m].
        heading: direction the car faces [rad].
        speed: ground speed [m/s].
        centre_distance: signed distance to the centreline [m], + left of the driving direction.
        heading_error: car heading minus track heading [rad].
        track_index: nearest centreline segment.
        tiles_visited: road tiles touched so far.
        n_tiles: road tiles of the track.
        lap_complete: CarRacing's lap flag (≥ 95 % of tiles and back on the start tile).
    """

    step: int
    x: float
    y: float
    heading: float
    speed: float
    centre_distance: float
    heading_error: float
    track_index: int
    tiles_visited: int
    n_tiles: int
    lap_complete: bool

    @property
    def off_track(self) -> bool:
        """More than one track half-width off the centreline (NVIDIA's intervention rule)."""
        return abs(self.centre_distance) > HALF_WIDTH


@dataclass(frozen=True)
class SimStep:
    """Result of :meth:`DrivingSim.step` (and :meth:`DrivingSim.step_on_track`, whose ``left``
    is the telemetry at which the car left the track, before it was put back; ``None`` when it
    stayed on it)."""

    frame: NDArray[np.uint8]
    telemetry: Telemetry
    reward: float
    terminated: bool
    truncated: bool
    left: Telemetry | None = None


@dataclass
class DrivingSim:
    """CarRacing-v3 with a forward camera, telemetry and interventions.

    Args:
        camera: ``"front"`` (perspective, :attr:`camera_spec`) or ``"topdown"`` (96×96 built-in).
        camera_spec: front camera geometry (66×200 default; 160×320 for Udacity-size frames).
        side_shift: lateral offset of the left/right cameras [m].
        max_steps: steps before the episode is truncated (CarRacing's default is 1000).
    """

    camera: Camera = "front"
    camera_spec: CameraSpec = field(default_factory=CameraSpec)
    side_shift: float = 1.5
    max_steps: int = 1000

    def __post_init__(self) -> None:
        if self.camera not in ("front", "topdown"):
            raise ValueError(f"camera: {self.camera!r} (must be 'front' or 'topdown')")
        gym = _gym()
        self._env = gym.make(
            "CarRacing-v3", max_episode_steps=self.max_steps, disable_env_checker=True
        )
        if self.camera == "front":
            self._skip_topdown_render()
        self._rays: GroundRays = ground_rays(self.camera_spec)
        self._raster: TrackRaster | None = None
        self.geometry: TrackGeometry | None = None
        self._obs: NDArray[np.uint8] | None = None
        self._step = 0
        self._lap = False

    def _skip_topdown_render(self) -> None:
        """Skip CarRacing's pygame top-down render on every step when it is not the camera.

        CarRacing draws all ~700 road polygons with pygame each step to make its observation
        (90 % of a step's time); with the front camera that image is never used, so the
        instance's ``_render`` returns a blank 96×96 frame for ``"state_pixels"`` instead.
        """
        u = self._env.unwrapped
        original = u._render
        blank = np.zeros((96, 96, 3), dtype=np.uint8)

        def render(mode: str, *args: Any, **kwargs: Any) -> Any:
            if mode == "state_pixels":
                return blank
            return original(mode, *args, **kwargs)

        u._render = render

    # ------------------------------------------------------------------ episode
    def reset(self, seed: int) -> tuple[NDArray[np.uint8], Telemetry]:
        """Start an episode on the track of ``seed`` (same seed, same track and start)."""
        obs, _ = self._env.reset(seed=int(seed))
        u = self._env.unwrapped
        pts = np.array([[t[2], t[3]] for t in u.track], dtype=float)
        self.geometry = track_geometry(pts)
        polys: list[NDArray[np.float64]] = []
        classes: list[int] = []
        for k, (verts, color) in enumerate(u.road_poly):
            polys.append(np.asarray(verts, dtype=float))
            c = np.asarray(color, dtype=float)
            if c[0] > 200 and c[1] > 200:
                classes.append(KERB_WHITE)
            elif c[0] > 200:
                classes.append(KERB_RED)
            else:
                classes.append(ROAD_A if k % 2 == 0 else ROAD_B)
        self._raster = rasterize_track(polys, classes)
        self._obs = np.asarray(obs)
        self._step = 0
        self._lap = False
        tel = self.telemetry()
        return self.frame(), tel

    def step(self, steer: float, throttle: float) -> SimStep:
        """Advance one frame (1/50 s).

        Args:
            steer: normalised steering in [-1, 1] (+ right).
            throttle: in [-1, 1]: gas when positive, brake when negative.

        Returns:
            The new frame, telemetry, CarRacing's reward and its termination flags.
        """
        s = float(np.clip(steer, -1.0, 1.0)) * MAX_WHEEL_ANGLE
        th = float(np.clip(throttle, -1.0, 1.0))
        action = np.array([s, max(th, 0.0), 0.8 * max(-th, 0.0)], dtype=np.float32)
        obs, reward, terminated, truncated, _ = self._env.step(action)
        self._obs = np.asarray(obs)
        self._step += 1
        self._lap = bool(self._env.unwrapped.new_lap)
        return SimStep(self.frame(), self.telemetry(), float(reward), terminated, truncated)

    def close(self) -> None:
        """Release the environment."""
        self._env.close()

    # ------------------------------------------------------------------ sensing
    def pose(self) -> tuple[float, float, float]:
        """``(x [m], y [m], heading [rad])`` of the car (heading = direction it faces)."""
        hull = self._env.unwrapped.car.hull
        return float(hull.position[0]), float(hull.position[1]), float(hull.angle + np.pi / 2)

    def telemetry(self) -> Telemetry:
        """Current telemetry (see :class:`Telemetry`)."""
        assert self.geometry is not None, "reset() first"
        u = self._env.unwrapped
        x, y, heading = self.pose()
        v = u.car.hull.linearVelocity
        i, _, d = project(self.geometry, x, y)
        return Telemetry(
            step=self._step,
            x=x,
            y=y,
            heading=heading,
            speed=float(np.hypot(v[0], v[1])),
            centre_distance=d,
            heading_error=float(wrap_to_pi(heading - self.geometry.heading[i])),
            track_index=i,
            tiles_visited=int(u.tile_visited_count),
            n_tiles=len(u.track),
            lap_complete=self._lap,
        )

    def front_view(self, lateral_shift: float = 0.0) -> NDArray[np.uint8]:
        """The forward camera image, shifted ``lateral_shift`` [m] to the left (− right)."""
        assert self._raster is not None, "reset() first"
        x, y, heading = self.pose()
        return render_view(self._raster, self._rays, x, y, heading, lateral_shift=lateral_shift)

    def side_views(self) -> tuple[NDArray[np.uint8], NDArray[np.uint8], NDArray[np.uint8]]:
        """``(left, centre, right)`` forward images, as the Udacity car's three cameras."""
        return (
            self.front_view(self.side_shift),
            self.front_view(0.0),
            self.front_view(-self.side_shift),
        )

    def topdown_view(self) -> NDArray[np.uint8]:
        """CarRacing's own 96×96 top-down observation."""
        assert self._obs is not None, "reset() first"
        return self._obs

    @property
    def frame_shape(self) -> tuple[int, int]:
        """(H, W) of :meth:`frame`."""
        if self.camera == "front":
            return self.camera_spec.height_px, self.camera_spec.width_px
        return 96, 96

    def frame(self) -> NDArray[np.uint8]:
        """The image of the configured camera."""
        return self.front_view() if self.camera == "front" else self.topdown_view()

    # ------------------------------------------------------------------ interventions
    def step_on_track(self, steer: float, throttle: float) -> SimStep:
        """:meth:`step`, then, when the car left the track, the intervention :meth:`put_back`:
        the frame and telemetry are those after it, ``left`` the telemetry before it."""
        st = self.step(steer, throttle)
        if not st.telemetry.off_track:
            return st
        back = self.put_back()
        return dataclasses.replace(st, frame=self.frame(), telemetry=back, left=st.telemetry)

    def put_back(self) -> Telemetry:
        """Intervention: put the car at rest on the nearest centreline point, facing along it."""
        from gymnasium.envs.box2d.car_dynamics import Car

        assert self.geometry is not None, "reset() first"
        u = self._env.unwrapped
        x, y, _ = self.pose()
        i, _, _ = project(self.geometry, x, y)
        px, py = self.geometry.points[i]
        u.car.destroy()
        u.car = Car(u.world, float(self.geometry.heading[i] - np.pi / 2), float(px), float(py))
        return self.telemetry()
