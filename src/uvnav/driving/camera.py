"""A forward-looking perspective camera rendered from a car pose over the track polygons.

The thesis (Chapter 6, Fig. 6.1) records three windscreen cameras of the Udacity simulator: left,
centre and right.  CarRacing-v3 only has a top-down view, so this module renders the driver's
view itself: a pinhole camera at height ``height`` above the ground, pitched down by ``pitch``,
looking along the car's heading, over a raster map of the track (grass with CarRacing's
chequered patches, road tiles in two shades, red/white kerbs) and a sky above the horizon.

Why our own renderer and not pygame/OpenGL: the ground is flat, so every pixel below the horizon
sees one ground point whose position in the car frame is fixed by the camera geometry; a frame is
one rigid transform of those precomputed points and one table lookup (about 0.2 ms for 66×200 on
one core), with no window, GPU or OpenGL context — it runs headless anywhere CarRacing runs.

Pure functions on numpy arrays: :func:`rasterize_track` (polygons → class map),
:func:`ground_rays` (camera geometry → ground points in the car frame),
:func:`render_view` (pose + map → RGB image).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: class ids of the raster map
GRASS, ROAD_A, ROAD_B, KERB_RED, KERB_WHITE = 0, 1, 2, 3, 4
#: RGB of the classes, then of the alternate grass patch and the sky (CarRacing's palette)
PALETTE = np.array(
    [
        [102, 204, 102],  # grass
        [102, 102, 102],  # road
        [112, 112, 112],  # road, alternate tile
        [255, 0, 0],  # kerb red
        [255, 255, 255],  # kerb white
        [102, 230, 102],  # grass, alternate patch
        [135, 180, 235],  # sky
        [90, 170, 90],  # far ground (beyond the far plane)
    ],
    dtype=np.uint8,
)
_GRASS_ALT, _SKY, _FAR = 5, 6, 7


@dataclass(frozen=True)
class CameraSpec:
    """Pinhole camera on the car.

    Attributes:
        height_px: image height [px].
        width_px: image width [px].
        fov: horizontal field of view [rad].  120°: with 90° the expert's pure-pursuit aim
            point lay outside the image in 7 % of the recorded frames (the recoveries the
            recording noise creates), and those frames held 68 % of the validation steering
            error; 120° (Udacity's Unity camera at its default 60° vertical is ≈ 98° across a
            2:1 frame) lowered the thesis-size validation MSE from 0.057 to 0.041 on the same
            labels and split (docs/thesis-notes.md, Chapter 6).
        mount_height: camera height above the ground [m] (CarRacing units).
        pitch: downward tilt of the optical axis [rad].
        forward: camera position ahead of the car's centre [m].
        far: ground points farther than this are drawn as far ground [m].
    """

    height_px: int = 66
    width_px: int = 200
    fov: float = np.deg2rad(120.0)
    mount_height: float = 3.0
    pitch: float = np.deg2rad(8.0)
    forward: float = 1.0
    far: float = 150.0


@dataclass(frozen=True)
class TrackRaster:
    """Class map of the track: ``classes[i, j]`` is the class at x = x0 + j·res, y = y0 + i·res."""

    classes: NDArray[np.uint8]
    x0: float
    y0: float
    res: float


def rasterize_track(
    polygons: list[NDArray[np.float64]],
    classes: list[int],
    *,
    margin: float = 5.0,
    res: float = 0.25,
) -> TrackRaster:
    """Rasterise the track polygons into a class map (later polygons drawn over earlier ones).

    Args:
        polygons: list of ``(k, 2)`` vertex arrays [m].
        classes: class id of each polygon (``ROAD_A``, ``ROAD_B``, ``KERB_RED``, ``KERB_WHITE``).
        margin: grass border around the polygons' bounding box [m].
        res: cell size [m].

    Returns:
        The raster (grass everywhere the polygons do not cover).
    """
    from PIL import Image, ImageDraw

    allp = np.concatenate([np.asarray(p, dtype=float) for p in polygons])
    x0, y0 = allp.min(axis=0) - margin
    x1, y1 = allp.max(axis=0) + margin
    nx, ny = int(np.ceil((x1 - x0) / res)), int(np.ceil((y1 - y0) / res))
    img = Image.new("L", (nx, ny), GRASS)
    draw = ImageDraw.Draw(img)
    for poly, cls in zip(polygons, classes, strict=True):
        pts = (np.asarray(poly, dtype=float) - [x0, y0]) / res
        draw.polygon([(float(p[0]), float(p[1])) for p in pts], fill=int(cls))
    return TrackRaster(np.asarray(img, dtype=np.uint8), float(x0), float(y0), res)


@dataclass(frozen=True)
class GroundRays:
    """Per-pixel ground geometry of a camera (see :func:`ground_rays`).

    Attributes:
        points: ``(H, W, 2)`` ground point in the car frame (x forward, y left) [m]; 0 where not
            ``ground``.
        ground: ``(H, W)`` true where the ray meets the ground within the far plane.
        below: ``(H, W)`` true where the ray points below the horizon at all.
    """

    points: NDArray[np.float64]
    ground: NDArray[np.bool_]
    below: NDArray[np.bool_]


def ground_rays(spec: CameraSpec) -> GroundRays:
    """Ground point seen by every pixel, in the car frame (x forward, y left) [m].

    Args:
        spec: camera geometry.

    Returns:
        The per-pixel ground points and masks.
    """
    h, w = spec.height_px, spec.width_px
    f = (w / 2) / np.tan(spec.fov / 2)  # focal length [px]
    u = np.arange(w) + 0.5 - w / 2  # right
    v = np.arange(h) + 0.5 - h / 2  # down
    uu, vv = np.meshgrid(u, v)
    # ray in camera coordinates: forward 1, left -u/f, up -v/f; then pitch down about the left axis
    fwd, left, up = np.ones_like(uu), -uu / f, -vv / f
    c, s = np.cos(spec.pitch), np.sin(spec.pitch)
    fwd_w = c * fwd + s * up
    up_w = -s * fwd + c * up
    down = -up_w
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(down > 1e-9, spec.mount_height / down, np.inf)
    px = spec.forward + t * fwd_w
    py = t * left
    dist = np.hypot(px, py)
    ground = np.isfinite(t) & (dist <= spec.far)
    pts = np.stack([np.where(ground, px, 0.0), np.where(ground, py, 0.0)], axis=-1)
    return GroundRays(pts, ground, np.isfinite(t))


def render_view(
    raster: TrackRaster,
    rays: GroundRays,
    x: float,
    y: float,
    heading: float,
    *,
    lateral_shift: float = 0.0,
) -> NDArray[np.uint8]:
    """Render the camera image at a car pose.

    Args:
        raster: the track's class map.
        rays: output of :func:`ground_rays` for the camera.
        x: car position x [m].
        y: car position y [m].
        heading: direction the car faces, from the x axis [rad].
        lateral_shift: camera offset to the car's left [m] (negative: right), as the Udacity
            car's left/right cameras.

    Returns:
        ``(H, W, 3)`` uint8 RGB image.
    """
    pts, ground = rays.points, rays.ground
    c, s = np.cos(heading), np.sin(heading)
    fx = pts[..., 0]
    fy = pts[..., 1] + lateral_shift
    wx = x + c * fx - s * fy
    wy = y + s * fx + c * fy
    ny, nx = raster.classes.shape
    j = np.floor((wx - raster.x0) / raster.res).astype(np.int64)
    i = np.floor((wy - raster.y0) / raster.res).astype(np.int64)
    inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx)
    cls = np.full(fx.shape, GRASS, dtype=np.int64)
    cls[inside] = raster.classes[i[inside], j[inside]]
    # CarRacing's grass has chequered patches of 20 m; alternate their shade
    patch = ((np.floor(wx / 20.0) + np.floor(wy / 20.0)) % 2).astype(bool)
    cls = np.where((cls == GRASS) & patch, _GRASS_ALT, cls)
    cls = np.where(ground, cls, _SKY)
    cls = np.where(~ground & rays.below, _FAR, cls)
    return PALETTE[cls]
