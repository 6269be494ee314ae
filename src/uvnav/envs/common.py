"""Pieces shared by the Chapter 3 and Chapter 4 environments (``uvnav/Nav3D-v0``,
``uvnav/UUV2D-v0``): comparing observations by content, the generic :class:`SimView` of
``info["uvnav"]``, loading a scene or a per-episode random scene, and painting polygons into an
RGB frame.  No gymnasium import here.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np


def content_equal(a: Any, b: Any) -> bool:
    """Equality by content: dataclasses field by field, numpy arrays element-wise (NaN equal to
    NaN), sequences and dicts item by item, anything else with ``==``.

    Gymnasium's determinism checks compare ``info`` dicts; the uvnav observations hold arrays,
    whose ``==`` is element-wise, hence this."""
    if a is b:
        return True
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        x, y = np.asarray(a), np.asarray(b)
        if x.shape != y.shape:
            return False
        if x.dtype.kind in "fc" and y.dtype.kind in "fc":
            return bool(np.array_equal(x, y, equal_nan=True))
        return bool(np.array_equal(x, y))
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        if type(a) is not type(b):
            return False
        return all(
            content_equal(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a)
        )
    if isinstance(a, list | tuple):
        if not isinstance(b, list | tuple) or len(a) != len(b):
            return False
        return all(content_equal(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        if not isinstance(b, dict) or a.keys() != b.keys():
            return False
        return all(content_equal(a[k], b[k]) for k in a)
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True
    return bool(a == b)


@dataclass(frozen=True, eq=False)
class SimView:
    """What a uvnav law is given at this decision (``info["uvnav"]`` of the Chapter 3 / 4 envs):
    its observation (:class:`~uvnav.sensors.sensing3d.Observation3D` or
    :class:`~uvnav.sensors.sonar2d.SonarObservation`) and its vehicle limits, plus the env's
    inverse action map ``to_action(command) -> action`` (what :func:`uvnav.envs.as_policy` uses).

    Equality compares the observation and the limits by content (:func:`content_equal`).
    """

    observation: Any
    spec: Any
    to_action: Callable[[Any], np.ndarray]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, SimView):
            return NotImplemented
        return content_equal(self.spec, other.spec) and content_equal(
            self.observation, other.observation
        )

    __hash__ = None  # type: ignore[assignment]


def scene_for_episode(
    scenario: Any, generators: Mapping[str, Callable[..., Any]], episode_seed: int
) -> Any:
    """The scene of an episode: ``scenario`` itself, or — when it names a generator without a
    seed (``"random-ch3"``) — that generator's scene number ``episode_seed`` (a fresh random
    scene every episode)."""
    if isinstance(scenario, str):
        return generators[scenario](episode_seed)
    return scenario


def fill_polygon(
    img: np.ndarray,
    polygon: np.ndarray,
    colour: tuple[int, int, int],
    gx: np.ndarray,
    gy: np.ndarray,
) -> None:
    """Paint the pixels of ``img`` whose centres (``gx``, ``gy``) [m] lie inside ``polygon``
    ((n, 2) [m]; even-odd rule via shapely) with ``colour`` (in place)."""
    import shapely

    if len(polygon) < 3:
        return
    poly = shapely.Polygon(np.asarray(polygon, dtype=float))
    if not poly.is_valid:
        poly = shapely.make_valid(poly)
    xmin, ymin, xmax, ymax = poly.bounds
    box = (gx >= xmin) & (gx <= xmax) & (gy >= ymin) & (gy <= ymax)
    if not box.any():
        return
    inside = np.zeros(gx.shape, dtype=bool)
    inside[box] = shapely.contains_xy(poly, gx[box], gy[box])
    img[inside] = colour


def pixel_grid(
    bounds: tuple[float, float, float, float], width: int, height: int
) -> tuple[np.ndarray, np.ndarray]:
    """Pixel-centre coordinates [m] of a ``height`` x ``width`` frame over ``bounds``
    ``(xmin, ymin, xmax, ymax)``, y up."""
    xmin, ymin, xmax, ymax = bounds
    xs = xmin + (np.arange(width) + 0.5) * (xmax - xmin) / width
    ys = ymax - (np.arange(height) + 0.5) * (ymax - ymin) / height
    gx, gy = np.meshgrid(xs, ys)
    return gx, gy


def square_bounds(points: np.ndarray, margin: float) -> tuple[float, float, float, float]:
    """The smallest square ``(xmin, ymin, xmax, ymax)`` [m] around ``points`` (n, 2), grown by
    ``margin`` [m]."""
    lo = points.min(axis=0) - margin
    hi = points.max(axis=0) + margin
    side = float(max(hi - lo))
    mid = 0.5 * (lo + hi)
    return (mid[0] - side / 2, mid[1] - side / 2, mid[0] + side / 2, mid[1] + side / 2)
