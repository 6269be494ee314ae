"""Terrain (thesis Ch. 7 §7.2): bilinear heights, generators, loaders, Jacksboro DEM, areas."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import box

from uvnav.recon import terrain as T  # noqa: N812


@settings(max_examples=50, deadline=None)
@given(
    a=st.floats(-2, 2),
    b=st.floats(-2, 2),
    c=st.floats(-50, 50),
    x=st.floats(0, 95),
    y=st.floats(0, 70),
)
def test_bilinear_reproduces_planes(a: float, b: float, c: float, x: float, y: float) -> None:
    xs = np.arange(0, 101, 5.0)
    ys = np.arange(0, 76, 2.5)
    X, Y = np.meshgrid(xs, ys)
    t = T.Terrain(a * X + b * Y + c, 0.0, 0.0, 5.0, 2.5)
    assert float(t.height(np.array(x), np.array(y))) == pytest.approx(a * x + b * y + c, abs=1e-9)


def test_bilinear_at_nodes_and_clamped_outside() -> None:
    z = np.arange(12.0).reshape(3, 4)
    t = T.Terrain(z, 10.0, 20.0, 2.0, 3.0)
    X, Y = np.meshgrid(t.xs, t.ys)
    np.testing.assert_allclose(t.height(X, Y), z)
    assert float(t.height(np.array(-100.0), np.array(-100.0))) == z[0, 0]
    assert float(t.height(np.array(1e4), np.array(1e4))) == z[-1, -1]


def test_fractal_is_seeded_and_scaled() -> None:
    a = T.fractal_terrain((200.0, 100.0), cell=5.0, seed=3, relief=30.0)
    b = T.fractal_terrain((200.0, 100.0), cell=5.0, seed=3, relief=30.0)
    c = T.fractal_terrain((200.0, 100.0), cell=5.0, seed=4, relief=30.0)
    np.testing.assert_array_equal(a.z, b.z)
    assert not np.array_equal(a.z, c.z)
    assert a.shape == (21, 41)
    assert a.z.min() == pytest.approx(0.0) and a.z.max() == pytest.approx(30.0)
    urban = T.fractal_terrain((200.0, 100.0), cell=5.0, seed=3, relief=30.0, n_blocks=5)
    assert urban.z.max() > a.z.max()


def test_jacksboro_crop_is_metric_and_documented() -> None:
    t = T.load_jacksboro()
    assert t.shape == (64, 64)
    # 3 arc-seconds at latitude ~36.6 deg, scaled by 1/6
    assert t.dy == pytest.approx(3 * 30.87 / 6, rel=1e-6)
    assert t.dx == pytest.approx(3 * 30.87 * np.cos(np.radians(36.59)) / 6, rel=1e-3)
    assert t.bounds[2] > 700.0 and t.bounds[3] > 900.0  # room for the 600 m x 600 m area
    assert 50.0 < float(np.ptp(t.z)) < 500.0
    assert "Jacksboro" in t.source


def test_loaders_roundtrip(tmp_path: Path) -> None:
    z = np.random.default_rng(0).uniform(0, 10, (6, 7))
    np.save(tmp_path / "dem.npy", z)
    t = T.load_dem(tmp_path / "dem.npy", cell=2.0)
    np.testing.assert_array_equal(t.z, z)
    assert t.dx == 2.0
    np.savez(tmp_path / "dem.npz", z=z, dx=3.0, dy=4.0, x0=1.0, y0=2.0)
    t = T.load_dem(tmp_path / "dem.npz")
    assert (t.dx, t.dy, t.x0, t.y0) == (3.0, 4.0, 1.0, 2.0)
    np.savez(tmp_path / "bad.npz", q=z)
    with pytest.raises(ValueError, match=r"bad\.npz"):
        T.load_dem(tmp_path / "bad.npz")
    with pytest.raises(ValueError, match="unknown DEM format"):
        T.load_dem(tmp_path / "dem.txt")


def test_geotiff_roundtrip(tmp_path: Path) -> None:
    rasterio = pytest.importorskip("rasterio")
    z = np.arange(20.0, dtype=np.float32).reshape(4, 5)  # row 0 = north
    path = tmp_path / "dem.tif"
    with rasterio.open(
        path,
        "w",
        driver="GTiff",
        height=4,
        width=5,
        count=1,
        dtype="float32",
        crs="EPSG:32617",
        transform=rasterio.Affine(10.0, 0.0, 1000.0, 0.0, -10.0, 2000.0),
    ) as ds:
        ds.write(z, 1)
    t = T.load_dem(path)
    np.testing.assert_array_equal(t.z, z[::-1])  # south-up rows
    assert (t.dx, t.dy) == (10.0, 10.0)
    assert t.x0 == pytest.approx(1005.0) and t.y0 == pytest.approx(2000.0 - 35.0)
    # the north-west cell centre keeps its height
    assert float(t.height(np.array(1005.0), np.array(1995.0))) == pytest.approx(0.0)


def test_area_checks() -> None:
    t = T.Terrain(np.zeros((11, 11)), 0.0, 0.0, 10.0, 10.0)
    T.check_area_inside(t, box(0, 0, 100, 100))
    with pytest.raises(ValueError, match=r"^area"):
        T.check_area_inside(t, box(50, 50, 150, 100))
    with pytest.raises(ValueError, match=r"^area"):
        T.area_polygon(np.array([[0, 0], [1, 1], [1, 0], [0, 1]]))
    with pytest.raises(ValueError, match=r"^terrain"):
        T.Terrain(np.array([[0.0, np.nan], [0.0, 0.0]]))
    assert T.square_area(10.0, center=(5.0, 5.0)).bounds == (0.0, 0.0, 10.0, 10.0)
    nodes = t.nodes_in(box(0, 0, 20, 20))
    assert len(nodes) == 9


def _forged_npy(shape: tuple[int, ...]) -> bytes:
    """A .npy header claiming ``shape`` float64 values, followed by 64 bytes only."""
    import io

    buf = io.BytesIO()
    header = {"descr": "<f8", "fortran_order": False, "shape": shape}
    np.lib.format.write_array_header_1_0(buf, header)
    return buf.getvalue() + bytes(64)


def test_a_forged_header_is_refused_before_any_allocation(tmp_path: Path) -> None:
    import zipfile

    npy = tmp_path / "huge.npy"
    npy.write_bytes(_forged_npy((1_000_000, 1_000_000)))
    with pytest.raises(ValueError, match=r"huge\.npy: array: the header claims shape \(1000000, "):
        T.load_dem(npy)
    npz = tmp_path / "huge.npz"
    with zipfile.ZipFile(npz, "w") as zf:
        zf.writestr("z.npy", _forged_npy((1000, 1000)))  # within the limit, but 64 bytes of data
    with pytest.raises(ValueError, match=r"array 'z': .* but only 64 bytes follow it"):
        T.load_dem(npz)


def test_heights_and_coordinates_outside_the_physical_range_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"height of 1e\+300 m is outside .* \|z\| <= 100000 m"):
        T.Terrain(np.array([[0.0, 1e300], [0.0, 0.0]]))
    with pytest.raises(ValueError, match=r"outside \|x\|, \|y\| <= 1e\+08 m"):
        T.Terrain(np.zeros((2, 2)), x0=1e15)
    path = tmp_path / "far.npz"
    np.savez(path, z=np.zeros((3, 3)), y0=-2e8)
    with pytest.raises(ValueError, match=r"far\.npz: terrain: the grid spans"):
        T.load_dem(path)
    assert T.Terrain(np.full((2, 2), 8848.0), x0=500_000.0, y0=6_250_000.0).shape == (2, 2)


def test_a_geotiff_without_crs_is_refused(tmp_path: Path) -> None:
    rasterio = pytest.importorskip("rasterio")
    path = tmp_path / "nocrs.tif"
    profile = {"driver": "GTiff", "height": 4, "width": 5, "count": 1, "dtype": "float32"}
    transform = rasterio.Affine(10.0, 0.0, 1000.0, 0.0, -10.0, 2000.0)
    with rasterio.open(path, "w", transform=transform, **profile) as ds:
        ds.write(np.zeros((4, 5), dtype=np.float32), 1)
    with pytest.raises(ValueError, match=r"nocrs\.tif: GeoTIFF has no CRS; .* metric CRS"):
        T.load_dem(path)
