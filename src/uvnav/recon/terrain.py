"""Terrain z_g = F(x_g, y_g) on a regular grid and the target area D (thesis Ch. 7 §7.2, eq. (7.1)).

Thesis: Y. Zhang, Ch. 7 "A Method for UAV Reconnaissance and Surveillance in Complex Environments"
(J. Zhang and Y. Zhang, ICCAR 2020).  The chapter states the ground as an elevation function
``z_g = F(x_g, y_g)`` and the target area ``D`` as a subset of the plane; it does not say where the
terrain comes from.  Here a terrain is a digital elevation model (DEM) on a regular grid with
bilinear interpolation between nodes, and ``D`` is a shapely polygon in the same metric frame.

Three sources (all pure except the explicit loaders at the bottom, which the CLI/bench call):

* :func:`fractal_terrain` — 1/f^beta ("fractal") noise synthesised in the Fourier domain from a
  seeded ``numpy.random.Generator``, with optional box-shaped "urban" blocks as occluders;
* :func:`load_dem` — a GeoTIFF (via rasterio; the ``recon`` extra) or a ``.npy``/``.npz`` array;
* :func:`load_jacksboro` — the USGS Jacksboro-fault DEM shipped inside matplotlib
  (``matplotlib.cbook.get_sample_data("jacksboro_fault_dem.npz")``: 3 arc-second cells,
  elevations in metres).  Lat/lon are turned into metres with a local equirectangular projection
  (1 arc-second of latitude = 30.87 m; longitude scaled by cos(latitude)).  Its native cells are
  ~93 m x ~75 m, far coarser than the chapter's 300 m / 600 m areas, so the documented default
  (:data:`JACKSBORO_DEFAULT`) crops a 64 x 64-cell window (rows 140:204 from the south, columns
  170:234) and scales it by 1/6 both horizontally and vertically — a geometrically similar model
  (slopes and occlusions preserved) about 795 m x 990 m with ~12.4 m x 15.4 m cells.  The crop
  and scale factors are parameters and are recorded in the returned terrain's ``source``.

Heights outside the grid are clamped to the edge values (the lattice can put a waypoint up to R
outside D; D itself must lie inside the DEM, which :func:`check_area_inside` enforces).

Units: lengths [m].
"""

from __future__ import annotations

import math
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import Polygon, box

from uvnav.validation import load_npy, load_npz, one_line

FloatArray = np.ndarray

#: Most nodes of a terrain grid, loaded or generated (10^8 nodes: 800 MB of float64 heights); a
#: module constant: raise it before loading for a larger DEM.
MAX_TERRAIN_NODES = 100_000_000

#: Largest terrain height magnitude [m] (the Earth's relief spans -11 km to +9 km).
MAX_HEIGHT = 1e5
#: Largest magnitude [m] of a terrain's planar coordinates (the Earth's circumference is 4e7 m;
#: projected eastings and northings stay below it).
MAX_MAP_COORDINATE = 1e8

#: Metres per arc-second of latitude (WGS84 mean) used by the equirectangular projection.
METRES_PER_ARCSEC = 30.87


@dataclass(frozen=True)
class Terrain:
    """A DEM on a regular grid: ``z[j, i]`` is the height [m] at ``(x0 + i*dx, y0 + j*dy)``.

    Attributes:
        z: Heights [m], shape (ny, nx), row j = northing index (increasing y).
        x0: Easting of node (0, 0) [m].
        y0: Northing of node (0, 0) [m].
        dx: Node spacing along x [m] (> 0).
        dy: Node spacing along y [m] (> 0).
        source: Human-readable provenance (generator and seed, file, crop and scale).
    """

    z: FloatArray
    x0: float = 0.0
    y0: float = 0.0
    dx: float = 1.0
    dy: float = 1.0
    source: str = ""
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        z = np.asarray(self.z, dtype=float)
        if z.ndim != 2 or min(z.shape) < 2:
            raise ValueError(
                f"terrain z: need a 2D grid of at least 2x2 nodes, got shape {z.shape}"
            )
        if not np.all(np.isfinite(z)):
            raise ValueError("terrain z: heights must be finite (fill no-data before use)")
        if not all(math.isfinite(v) for v in (self.x0, self.y0, self.dx, self.dy)):
            raise ValueError(
                f"terrain: origin and cell sizes must be finite, got x0={self.x0}, "
                f"y0={self.y0}, dx={self.dx}, dy={self.dy}"
            )
        if not (self.dx > 0 and self.dy > 0):
            raise ValueError(
                f"terrain: cell sizes must be positive, got dx={self.dx}, dy={self.dy}"
            )
        peak = float(np.abs(z).max())
        if peak > MAX_HEIGHT:
            raise ValueError(
                f"terrain z: a height of {peak:g} m is outside the physical range "
                f"|z| <= {MAX_HEIGHT:g} m (uvnav.recon.terrain.MAX_HEIGHT)"
            )
        ny, nx = z.shape
        corners = (self.x0, self.y0, self.x0 + self.dx * (nx - 1), self.y0 + self.dy * (ny - 1))
        if max(abs(c) for c in corners) > MAX_MAP_COORDINATE:
            raise ValueError(
                f"terrain: the grid spans x {corners[0]:g}..{corners[2]:g} m, y {corners[1]:g}.."
                f"{corners[3]:g} m, outside |x|, |y| <= {MAX_MAP_COORDINATE:g} m "
                "(uvnav.recon.terrain.MAX_MAP_COORDINATE)"
            )
        object.__setattr__(self, "z", z)

    @property
    def shape(self) -> tuple[int, int]:
        """Grid shape (ny, nx)."""
        return (int(self.z.shape[0]), int(self.z.shape[1]))

    @property
    def xs(self) -> FloatArray:
        """Node eastings [m], shape (nx,)."""
        return self.x0 + self.dx * np.arange(self.z.shape[1])

    @property
    def ys(self) -> FloatArray:
        """Node northings [m], shape (ny,)."""
        return self.y0 + self.dy * np.arange(self.z.shape[0])

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the grid nodes [m]."""
        return (
            self.x0,
            self.y0,
            self.x0 + self.dx * (self.z.shape[1] - 1),
            self.y0 + self.dy * (self.z.shape[0] - 1),
        )

    @property
    def cell(self) -> float:
        """The larger node spacing [m]."""
        return float(max(self.dx, self.dy))

    def height(self, x: FloatArray, y: FloatArray) -> FloatArray:
        """Bilinear height F(x, y) [m] at points (any broadcastable shapes); clamped outside."""
        return bilinear_heights(self.z, self.x0, self.y0, self.dx, self.dy, x, y)

    def nodes_in(self, area: Polygon) -> FloatArray:
        """Grid nodes (x, y, F) [m] inside the closed polygon ``area``, shape (m, 3)."""
        X, Y = np.meshgrid(self.xs, self.ys)
        inside = shapely.contains_xy(area, X, Y) | shapely.intersects_xy(area.boundary, X, Y)
        return np.column_stack([X[inside], Y[inside], self.z[inside]])


def bilinear_heights(
    z: FloatArray, x0: float, y0: float, dx: float, dy: float, x: FloatArray, y: FloatArray
) -> FloatArray:
    """Bilinear interpolation of grid ``z`` (ny, nx) at points (x, y) [m]; clamped at the edges."""
    ny, nx = z.shape
    fx = np.clip((np.asarray(x, dtype=float) - x0) / dx, 0.0, nx - 1.0)
    fy = np.clip((np.asarray(y, dtype=float) - y0) / dy, 0.0, ny - 1.0)
    i = np.minimum(fx.astype(np.intp), nx - 2)
    j = np.minimum(fy.astype(np.intp), ny - 2)
    tx = fx - i
    ty = fy - j
    z00 = z[j, i]
    z10 = z[j, i + 1]
    z01 = z[j + 1, i]
    z11 = z[j + 1, i + 1]
    return np.asarray(
        (z00 * (1 - tx) + z10 * tx) * (1 - ty) + (z01 * (1 - tx) + z11 * tx) * ty, dtype=float
    )


def fractal_heights(
    shape: tuple[int, int], rng: np.random.Generator, *, beta: float = 2.2, relief: float = 40.0
) -> FloatArray:
    """1/f^beta noise heights [m] on a grid ``shape`` (ny, nx), range scaled to ``relief``.

    Spectral synthesis: white complex noise shaped by |k|^(-beta/2) in amplitude (power ~ 1/f^beta)
    and transformed back with ``numpy.fft.irfft2``; beta ~ 2 gives natural-looking hills.
    """
    ny, nx = shape
    ky = np.fft.fftfreq(ny)[:, None]
    kx = np.fft.rfftfreq(nx)[None, :]
    k = np.hypot(kx, ky)
    k[0, 0] = 1.0
    amp = k ** (-beta / 2.0)
    amp[0, 0] = 0.0
    noise = rng.standard_normal(amp.shape) + 1j * rng.standard_normal(amp.shape)
    h = np.fft.irfft2(noise * amp, s=(ny, nx))
    span = float(h.max() - h.min())
    return (h - h.min()) * (relief / span if span > 0 else 0.0)


def terrain_nodes(size: tuple[float, float], cell: float) -> float:
    """Nodes of a (width, height) [m] grid at spacing ``cell`` [m] (inf when not finite)."""
    if not (cell > 0 and all(math.isfinite(v) and v >= 0 for v in (*size, cell))):
        return math.inf
    return (size[0] / cell + 1.0) * (size[1] / cell + 1.0)


def fractal_terrain(
    size: tuple[float, float],
    *,
    cell: float = 5.0,
    seed: int = 0,
    origin: tuple[float, float] = (0.0, 0.0),
    relief: float = 40.0,
    beta: float = 2.2,
    n_blocks: int = 0,
    block_size: tuple[float, float] = (15.0, 40.0),
    block_height: tuple[float, float] = (10.0, 30.0),
) -> Terrain:
    """Generated terrain: fractal hills plus optional box "urban" blocks (occluders).

    Args:
        size: (width, height) of the DEM [m].
        cell: Node spacing [m].
        seed: Seed of the ``numpy.random.Generator`` (same seed, same terrain).
        origin: (x, y) of the south-west node [m].
        relief: Peak-to-trough height of the hills [m].
        beta: Spectral exponent of the 1/f^beta noise.
        n_blocks: Number of rectangular blocks added on top (buildings).
        block_size: Range of block side lengths [m].
        block_height: Range of block heights above the hills [m].
    """
    nodes = terrain_nodes(size, cell)
    if nodes > MAX_TERRAIN_NODES:
        raise ValueError(
            f"terrain: {size[0]:g} m x {size[1]:g} m at cell {cell:g} m is {nodes:.3g} nodes, more "
            f"than the limit of {MAX_TERRAIN_NODES:.0e} (uvnav.recon.terrain.MAX_TERRAIN_NODES)"
        )
    rng = np.random.default_rng(seed)
    nx = round(size[0] / cell) + 1
    ny = round(size[1] / cell) + 1
    z = fractal_heights((ny, nx), rng, beta=beta, relief=relief)
    xs = origin[0] + cell * np.arange(nx)
    ys = origin[1] + cell * np.arange(ny)
    X, Y = np.meshgrid(xs, ys)
    for _ in range(n_blocks):
        w, h = rng.uniform(*block_size, size=2)
        cx = rng.uniform(xs[0], xs[-1])
        cy = rng.uniform(ys[0], ys[-1])
        top = rng.uniform(*block_height)
        inside = (np.abs(X - cx) <= w / 2) & (np.abs(Y - cy) <= h / 2)
        if inside.any():
            z[inside] = z[inside].max() + top
    return Terrain(
        z,
        origin[0],
        origin[1],
        cell,
        cell,
        source=f"fractal 1/f^{beta} seed={seed} relief={relief} m blocks={n_blocks}",
        meta={"seed": seed, "relief": relief, "beta": beta, "n_blocks": n_blocks},
    )


@dataclass(frozen=True)
class JacksboroCrop:
    """How the Jacksboro DEM is cropped and scaled (documented default :data:`JACKSBORO_DEFAULT`).

    Attributes:
        row0: First row of the crop (south edge after flipping to north-up rows).
        col0: First column of the crop.
        n: Crop size in cells (n x n).
        horizontal_scale: Factor applied to the metric cell size (1.0 = true metres).
        vertical_scale: Factor applied to the heights above the crop minimum.
    """

    row0: int = 140
    col0: int = 170
    n: int = 64
    horizontal_scale: float = 1.0 / 6.0
    vertical_scale: float = 1.0 / 6.0


JACKSBORO_DEFAULT = JacksboroCrop()


def jacksboro_terrain(data: dict[str, Any], crop: JacksboroCrop = JACKSBORO_DEFAULT) -> Terrain:
    """Terrain from the arrays of matplotlib's ``jacksboro_fault_dem.npz`` (pure; see loader).

    ``data`` holds ``elevation`` (rows north to south), ``dx``/``dy`` (cell size [deg],
    3 arc-seconds) and ``ymin``/``ymax`` (latitude range [deg]).  Rows are flipped to south-up,
    lat/lon converted to metres at
    the crop's mean latitude, then cropped and scaled by ``crop``; the origin is the crop's
    south-west node at (0, 0).
    """
    elev = np.asarray(data["elevation"], dtype=float)[::-1]
    dlat = 3600.0 * float(data.get("dy", 3.0 / 3600.0))  # [arc-second]
    dlon = 3600.0 * float(data.get("dx", 3.0 / 3600.0))
    # the file's ymin/ymax are swapped (36.73 / 36.45); only their mean is used
    lat0 = 0.5 * (float(data.get("ymin", 36.6)) + float(data.get("ymax", 36.6)))
    if crop.row0 + crop.n > elev.shape[0] or crop.col0 + crop.n > elev.shape[1]:
        raise ValueError(f"jacksboro crop {crop} exceeds the DEM shape {elev.shape}")
    z = elev[crop.row0 : crop.row0 + crop.n, crop.col0 : crop.col0 + crop.n]
    z = (z - z.min()) * crop.vertical_scale
    dy_m = dlat * METRES_PER_ARCSEC * crop.horizontal_scale
    dx_m = dlon * METRES_PER_ARCSEC * np.cos(np.radians(lat0)) * crop.horizontal_scale
    return Terrain(
        z,
        0.0,
        0.0,
        float(dx_m),
        float(dy_m),
        source=(
            f"USGS Jacksboro fault DEM (matplotlib sample), rows {crop.row0}:{crop.row0 + crop.n}, "
            f"cols {crop.col0}:{crop.col0 + crop.n}, horizontal x{crop.horizontal_scale:.4g}, "
            f"vertical x{crop.vertical_scale:.4g}"
        ),
        meta={"crop": crop, "lat0": lat0},
    )


def square_area(
    side: float,
    *,
    center: tuple[float, float] | None = None,
    corner: tuple[float, float] = (0.0, 0.0),
) -> Polygon:
    """The square target area D of side ``side`` [m] (by centre, or by south-west corner)."""
    if side <= 0:
        raise ValueError(f"area side must be positive, got {side}")
    if center is not None:
        return box(
            center[0] - side / 2, center[1] - side / 2, center[0] + side / 2, center[1] + side / 2
        )
    return box(corner[0], corner[1], corner[0] + side, corner[1] + side)


def area_polygon(coords: FloatArray) -> Polygon:
    """D as a valid shapely polygon from vertices (n, 2) [m]; raises ``ValueError`` if invalid."""
    v = np.asarray(coords, dtype=float)
    if v.ndim != 2 or v.shape[1] != 2 or len(v) < 3:
        raise ValueError(f"area: need at least 3 vertices (x, y), got shape {v.shape}")
    poly = Polygon(v)
    if not poly.is_valid or poly.area <= 0:
        raise ValueError("area: the polygon is self-intersecting or has zero area")
    return poly


def check_area_inside(terrain: Terrain, area: Polygon) -> None:
    """Raise ``ValueError`` when D is not inside the DEM's node rectangle."""
    xmin, ymin, xmax, ymax = terrain.bounds
    ax0, ay0, ax1, ay1 = area.bounds
    tol = 1e-9 * max(1.0, xmax - xmin, ymax - ymin)
    if ax0 < xmin - tol or ay0 < ymin - tol or ax1 > xmax + tol or ay1 > ymax + tol:
        raise ValueError(
            f"area: D bounds ({ax0:.1f}, {ay0:.1f}, {ax1:.1f}, {ay1:.1f}) m lie outside the DEM "
            f"({xmin:.1f}, {ymin:.1f}, {xmax:.1f}, {ymax:.1f}) m"
        )


# ------------------------------------------------------------------------ loaders (file I/O only)


def load_dem(path: str | Path, *, cell: float | None = None) -> Terrain:
    """Load a DEM from a GeoTIFF (rasterio, ``recon`` extra) or a ``.npy``/``.npz`` file.

    ``.npy``: a 2D height array (row 0 = south) with node spacing ``cell`` [m] (default 1 m).
    ``.npz``: key ``z`` (or ``elevation``) and optional ``dx``, ``dy``, ``x0``, ``y0`` [m].
    GeoTIFF: band 1 of a raster in a *projected* CRS (metres); rows are flipped to south-up and
    no-data cells are filled with the minimum valid height.

    Raises:
        ValueError: unknown suffix, or a file whose contents are not a usable DEM (the message
            names the file and the problem).
    """
    p = Path(path)
    suffix = p.suffix.lower()
    try:
        if suffix == ".npy":
            with p.open("rb") as fh:
                if fh.read(6) != b"\x93NUMPY":
                    raise OSError("no .npy header")
            z = load_npy(p, MAX_TERRAIN_NODES)
            c = 1.0 if cell is None else float(cell)
            return Terrain(_heights(z, "array"), 0.0, 0.0, c, c, source=f"{p.name}")
        if suffix == ".npz":
            d = load_npz(p, MAX_TERRAIN_NODES)
            key = "z" if "z" in d else "elevation" if "elevation" in d else None
            if key is None:
                raise ValueError("needs an array named 'z' (or 'elevation')")
            default = 1.0 if cell is None else float(cell)
            dx = _npz_number(d, "dx", default)
            dy = _npz_number(d, "dy", dx)
            x0 = _npz_number(d, "x0", 0.0)
            y0 = _npz_number(d, "y0", 0.0)
            return Terrain(_heights(d[key], key), x0, y0, dx, dy, source=p.name)
        if suffix in (".tif", ".tiff"):
            return _load_geotiff(p)
    except ValueError as exc:
        if "allow_pickle" in str(exc):  # numpy's refusal of an object array
            raise ValueError(f"{p}: holds pickled objects, which are never loaded") from None
        raise ValueError(f"{p}: {exc}") from None
    except (EOFError, OSError, zipfile.BadZipFile, KeyError) as exc:
        what = {".npy": "a .npy array", ".npz": "a .npz archive"}.get(suffix, "a DEM file")
        raise ValueError(f"{p}: not {what} ({exc or type(exc).__name__})") from None
    raise ValueError(f"{p}: unknown DEM format {suffix!r} (use .tif, .npy or .npz)")


def _heights(z: Any, name: str) -> FloatArray:
    """``z`` as float heights; a non-numeric array (strings, complex, objects) is refused."""
    a = np.asarray(z)
    if a.dtype.kind not in "biuf":
        raise ValueError(f"{name}: heights must be real numbers (got dtype {a.dtype})")
    if a.size > MAX_TERRAIN_NODES:
        raise ValueError(f"{name}: {a.size} nodes, more than the limit of {MAX_TERRAIN_NODES}")
    return np.asarray(a, dtype=float)


def _npz_number(d: Any, key: str, default: float) -> float:
    """The scalar ``d[key]`` (a finite real number) or ``default`` when absent."""
    if key not in d:
        return default
    a = np.asarray(d[key])
    if a.size != 1 or a.dtype.kind not in "biuf":
        raise ValueError(f"{key}: must be one real number (got {a.dtype} array of shape {a.shape})")
    v = float(a.reshape(()))
    if not math.isfinite(v):
        raise ValueError(f"{key}: must be a finite number (got {v})")
    return v


def _load_geotiff(p: Path) -> Terrain:
    try:
        import rasterio
    except ImportError as exc:  # pragma: no cover - depends on the extra
        raise ValueError("reading GeoTIFF needs rasterio: pip install 'uvnav[recon]'") from exc
    from rasterio.errors import RasterioError

    try:
        with rasterio.open(p) as ds:
            if ds.width * ds.height > MAX_TERRAIN_NODES:
                raise ValueError(
                    f"{ds.width} x {ds.height} nodes, more than the limit of {MAX_TERRAIN_NODES}"
                )
            band = ds.read(1, masked=True).astype(float)
            t = ds.transform
            if ds.crs is None:
                raise ValueError(
                    "GeoTIFF has no CRS; its coordinates must be in a projected, metric CRS "
                    "(assign one, e.g. gdal_edit.py -a_srs EPSG:32617)"
                )
            if ds.crs.is_geographic:
                raise ValueError(
                    "GeoTIFF CRS is geographic (degrees); reproject to a metric CRS first"
                )
            if abs(t.b) > 1e-12 or abs(t.d) > 1e-12:
                raise ValueError("GeoTIFF is rotated; only north-up rasters are supported")
            fill = float(band.min()) if band.count() else 0.0
            z = np.ma.filled(band, fill)
    except RasterioError as exc:
        raise ValueError(f"not a readable GeoTIFF ({one_line(str(exc))})") from None
    dx, dy = abs(t.a), abs(t.e)
    z = z[::-1] if t.e < 0 else z
    x0 = t.c + dx / 2
    y0 = (t.f + t.e * (z.shape[0] - 0.5)) if t.e < 0 else t.f + dy / 2
    return Terrain(np.ascontiguousarray(z), float(x0), float(y0), dx, dy, source=p.name)


def load_jacksboro(crop: JacksboroCrop = JACKSBORO_DEFAULT) -> Terrain:
    """The matplotlib-shipped USGS Jacksboro DEM, cropped and scaled by ``crop`` (no download)."""
    from matplotlib import cbook

    d: Any = cbook.get_sample_data("jacksboro_fault_dem.npz")  # an NpzFile for .npz names
    with d:
        data = {k: d[k] for k in d.files}
    return jacksboro_terrain(data, crop)
