"""Hostile-input corpus: every input surface crossed with hostile values, generated here.

Surfaces: a scene file's fields, ``-p`` law parameters, ``--gen-param`` generator parameters, a
campaign file's fields, the Gymnasium envs' constructor arguments and actions, and the files the
commands read (pedestrian tracks, DEMs, sonar datasets, driving logs and their images), each also
replaced by special files (a FIFO, ``/dev/zero``, a folder, a symlink to a device, an empty or a
binary file).  Values: NaN, ±inf, 1e300, 1e15, -1, 0, 2.5, huge integers, a number of 10^5
digits, empty values, wrong types, nested structures, 5,000-character strings, non-UTF-8 bytes.

A CLI case ends with exit status 0 and no NaN or inf in its (JSON) result, or with exit status 2
and exactly one line ``error: ...``; never a traceback.  An env case ends with finite observations
and rewards, or with one-line ``ValueError``/``TypeError``.  Every case runs in-process under a
deadline (``SIGALRM``): a hang fails it.  The successful runs use scenes of 1 s.
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import re
import signal
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from cli_runner import FastRunner
from uvnav.cli.app import app

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGALRM"), reason="needs SIGALRM")

#: seconds one case may take before it counts as a hang
DEADLINE = 20


runner = FastRunner()


class HangError(Exception):
    """A case ran past :data:`DEADLINE`."""


def _alarm(_signum: int, _frame: Any) -> None:
    raise HangError(f"no answer within {DEADLINE} s")


def within_deadline(fn: Callable[[], Any]) -> Any:
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(DEADLINE)
    try:
        return fn()
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


# ------------------------------------------------------------------------------- hostile values

#: raw YAML text of hostile values (a bytes value is written as is: not UTF-8)
YAML_VALUES: dict[str, str | bytes] = {
    "nan": ".nan",
    "inf": ".inf",
    "-inf": "-.inf",
    "1e300": "1.0e+300",
    "1e300-yaml11-string": "1.0e300",
    "1e15": "1.0e+15",
    "-1": "-1",
    "0": "0",
    "2.5": "2.5",
    "huge-int": "9" * 40,
    "1e5-digits": "1" * 100_000,
    "empty": "''",
    "null": "null",
    "list": "[1, 2]",
    "mapping": "{a: 1}",
    "nested": "[" * 200 + "]" * 200,
    "long-string": "'" + "x" * 5000 + "'",
    "bool": "true",
    "non-utf8": b"\xff\xfe\x80",
}

#: hostile values of a command-line option (``-p KEY=VALUE``, ``--gen-param KEY=VALUE``)
OPTION_VALUES: dict[str, str] = {
    k: v for k, v in YAML_VALUES.items() if isinstance(v, str) and k != "1e300-yaml11-string"
} | {"no-value": "", "surrogate": os.fsdecode(b"\xff")}

#: hostile Python values of an env argument
PY_VALUES: dict[str, Any] = {
    "nan": math.nan,
    "inf": math.inf,
    "-inf": -math.inf,
    "1e300": 1e300,
    "1e15": 1e15,
    "-1": -1,
    "0": 0,
    "2.5": 2.5,
    "1e9": 10**9,
    "10^400": 10**400,
    "empty": "",
    "long-string": "x" * 5000,
    "list": [1, 2],
    "mapping": {"a": 1},
    "none": None,
    "bool": True,
    "bytes": b"\xff",
}

#: hostile text of one number in a data file (a track, a driving log)
TEXT_NUMBERS: dict[str, str] = {
    "nan": "nan",
    "inf": "inf",
    "-inf": "-inf",
    "1e300": "1e300",
    "1e308": "1e308",
    "1e15": "1e15",
    "-1": "-1",
    "0": "0",
    "2.5": "2.5",
    "huge-int": "9" * 40,
    "1e5-digits": "1" * 100_000,
    "empty": "",
    "word": "abc",
    "long-string": "x" * 5000,
}

#: hostile numbers of an array file (a DEM, a sonar dataset)
ARRAY_NUMBERS: dict[str, float] = {
    "nan": math.nan,
    "inf": math.inf,
    "-inf": -math.inf,
    "1e300": 1e300,
    "1e15": 1e15,
    "-1": -1.0,
    "0": 0.0,
    "2.5": 2.5,
}

# --------------------------------------------------------------------------------- the checks


def _finite_json(value: Any) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, dict):
        return all(_finite_json(v) for v in value.values())
    if isinstance(value, list):
        return all(_finite_json(v) for v in value)
    return True


def check_cli(result: Any, *, as_json: bool) -> None:
    """A run (exit 0, finite numbers) or one ``error:`` line with exit 2; never a traceback."""
    out = result.output
    assert "Traceback" not in out, out[-2000:]
    exc = result.exception
    assert exc is None or isinstance(exc, SystemExit), repr(exc)
    if result.exit_code == 0:
        if as_json:
            lines = [ln for ln in out.splitlines() if ln.startswith("{")]
            assert lines, out[-2000:]
            assert all(_finite_json(json.loads(ln)) for ln in lines), out[-2000:]
        else:
            assert not re.search(r"\b(nan|inf)\b", out, re.IGNORECASE), out[-2000:]
        return
    lines = [ln for ln in out.splitlines() if ln.strip()]
    assert len(lines) == 1, f"expected one line, got:\n{out[-2000:]}"
    assert lines[0].startswith("error: "), lines[0][:500]
    assert result.exit_code == 2, f"exit {result.exit_code}: {lines[0][:500]}"


def _finite_result(value: Any) -> bool:
    if isinstance(value, dict):
        return all(_finite_result(v) for v in value.values())
    if isinstance(value, list | tuple):
        return all(_finite_result(v) for v in value)
    if isinstance(value, np.ndarray) and value.dtype.kind in "fc":
        return bool(np.isfinite(value).all())
    if isinstance(value, float | np.floating):
        return math.isfinite(value)
    return True


def check_env(fn: Callable[[], Any]) -> None:
    """Finite results, or one-line ``ValueError``/``TypeError``."""
    try:
        result = fn()
    except (ValueError, TypeError) as exc:
        message = str(exc)
        assert message and "\n" not in message, repr(message[:500])
        return
    assert _finite_result(result), result


# ------------------------------------------------------------------------------ shared inputs

SCENE: dict[str, Any] = {
    "name": "hostile",
    "dt": 0.1,
    "control_period": 0.1,
    "t_max": 1.0,
    "goal_tolerance": 0.1,
    "robot": {
        "model": "unicycle",
        "start": [0.0, 0.0],
        "goal": [3.0, 3.0],
        "v_max": 0.7,
        "u_max": 1.4,
        "radius": 0.1,
    },
    "sensing": {"range": 5.0, "velocities": "known", "position_noise": 0.0},
    "obstacles": [
        {
            "name": "disc",
            "body": {"disc": 0.5},
            "start": {"position": [0.0, 2.5], "heading": 0.0},
            "motion": {"type": "constant", "velocity": [0.1, 0.0]},
        },
        {
            "name": "triangle",
            "body": {"polygon": [[-0.5, -0.4], [0.6, -0.4], [0.0, 0.5]]},
            "start": {"position": [2.5, 0.0], "heading": 0.3},
            "motion": {"type": "constant", "velocity": [0.0, 0.1], "angular_velocity": 0.1},
        },
    ],
    "controller": {"name": "zhang2019-v1", "params": {"alpha0": 0.1}},
}

SCENE_FIELDS = (
    ("name",),
    ("dt",),
    ("t_max",),
    ("control_period",),
    ("goal_tolerance",),
    ("robot", "start", 0),
    ("robot", "goal", 1),
    ("robot", "v_max"),
    ("robot", "u_max"),
    ("robot", "radius"),
    ("sensing", "range"),
    ("sensing", "position_noise"),
    ("obstacles", 0, "body", "disc"),
    ("obstacles", 0, "start", "position", 0),
    ("obstacles", 0, "start", "heading"),
    ("obstacles", 0, "motion", "velocity", 0),
    ("obstacles", 1, "body", "polygon", 0, 0),
    ("obstacles", 1, "motion", "angular_velocity"),
    ("controller", "params", "alpha0"),
)

MARK = "HOSTILE-VALUE-HERE"


def _with_mark(data: Any, path: tuple[Any, ...]) -> Any:
    out = json.loads(json.dumps(data))
    node = out
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = MARK
    return out


def yaml_with(data: Any, path: tuple[Any, ...], raw: str | bytes) -> bytes:
    """``data`` as YAML bytes with the raw text ``raw`` at ``path``."""
    text = yaml.safe_dump(_with_mark(data, path), sort_keys=False, width=10**6)
    head, tail = text.encode().split(MARK.encode())
    return head + (raw if isinstance(raw, bytes) else raw.encode()) + tail


@pytest.fixture(scope="module")
def base(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder with the valid inputs the cases mutate, and the special files."""
    root = tmp_path_factory.mktemp("hostile")
    (root / "scene.yaml").write_text(yaml.safe_dump(SCENE, sort_keys=False))
    os.mkfifo(root / "fifo")
    (root / "folder").mkdir()
    (root / "zero-link").symlink_to("/dev/zero")
    (root / "empty").write_bytes(b"")
    (root / "binary").write_bytes(bytes(range(256)) * 4)
    return root


SPECIAL = {
    "fifo": lambda root: root / "fifo",
    "dev-zero": lambda root: Path("/dev/zero"),
    "symlink-to-dev-zero": lambda root: root / "zero-link",
    "folder": lambda root: root / "folder",
    "missing": lambda root: root / "missing",
    "empty": lambda root: root / "empty",
    "binary": lambda root: root / "binary",
    "long-name": lambda root: root / ("n" * 5000),
}


@dataclass(frozen=True)
class CliCase:
    """``make(base, tmp) -> argv``; ``as_json``: the command prints JSON on success."""

    id: str
    make: Callable[[Path, Path], list[str]]
    as_json: bool = True


@dataclass(frozen=True)
class EnvCase:
    """``run() -> results`` (observations, rewards)."""

    id: str
    run: Callable[[], Any]


# ----------------------------------------------------------------------------- CLI surfaces


def _scene_cases() -> Iterator[CliCase]:
    for path in SCENE_FIELDS:
        for name, raw in YAML_VALUES.items():

            def make(root: Path, tmp: Path, path: Any = path, raw: Any = raw) -> list[str]:
                f = tmp / "scene.yaml"
                f.write_bytes(yaml_with(SCENE, path, raw))
                return ["simulate", str(f), "--json"]

            yield CliCase(f"scene:{'.'.join(map(str, path))}={name}", make)


def _param_cases() -> Iterator[CliCase]:
    keys = (
        ("zhang2019-v1", "alpha0"),
        ("zhang2019-v1", "switch_distance"),
        ("zhang2019-v1", "tangent_rule"),
        ("zhang2019-v1", "turn_slowdown"),
        ("dwa-v1", "v_samples"),
        ("dwa-v1", "horizon"),
    )
    for law, key in keys:
        for name, raw in OPTION_VALUES.items():

            def make(root: Path, tmp: Path, law: str = law, arg: str = f"{key}={raw}") -> list[str]:
                return ["simulate", str(root / "scene.yaml"), "-c", law, "-p", arg, "--json"]

            yield CliCase(f"param:{law}:{key}={name}", make)
    for name, arg in (("no-equals", "alpha0"), ("no-key", "=1"), ("spaces", "al pha=1")):
        yield CliCase(
            f"param:zhang2019-v1:{name}",
            lambda root, tmp, arg=arg: ["simulate", str(root / "scene.yaml"), "-p", arg, "--json"],
        )


def _gen_param_cases() -> Iterator[CliCase]:
    for key in ("n_obstacles", "speed_ratio_max", "t_max", "dt", "body"):
        for name, raw in OPTION_VALUES.items():
            short = [] if key == "t_max" else ["--gen-param", "t_max=1"]

            def make(root: Path, tmp: Path, arg: str = f"{key}={raw}", short: Any = short) -> list:
                return ["simulate", "random-ch2:1", "--gen-param", arg, *short, "--json"]

            yield CliCase(f"gen-param:{key}={name}", make)
    for name, arg in (("no-equals", "x"), ("empty", ""), ("unknown", "bogus=1")):
        yield CliCase(
            f"gen-param:{name}",
            lambda root, tmp, arg=arg: ["simulate", "random-ch2:1", "--gen-param", arg, "--json"],
        )


CAMPAIGN: dict[str, Any] = {
    "name": "hostile",
    "description": "a hostile campaign",
    "scenarios": [{"file": "scene.yaml", "seeds": [0, 1]}],
    "controllers": [{"name": "zhang2019-v1", "params": {"alpha0": 0.1}, "oracle": False}],
    "record": False,
    "beyond_assumptions": False,
}

CAMPAIGN_FIELDS = (
    ("name",),
    ("description",),
    ("scenarios", 0, "seeds", 1),
    ("scenarios", 0, "file"),
    ("controllers", 0, "name"),
    ("controllers", 0, "params", "alpha0"),
    ("controllers", 0, "oracle"),
    ("record",),
    ("beyond_assumptions",),
)


def _campaign_cases() -> Iterator[CliCase]:
    for path in CAMPAIGN_FIELDS:
        for name, raw in YAML_VALUES.items():

            def make(root: Path, tmp: Path, path: Any = path, raw: Any = raw) -> list[str]:
                (tmp / "scene.yaml").write_bytes((root / "scene.yaml").read_bytes())
                f = tmp / "campaign.yaml"
                f.write_bytes(yaml_with(CAMPAIGN, path, raw))
                return ["bench", str(f), "--db", str(tmp / "r.sqlite"), "--workers", "1", "--json"]

            yield CliCase(f"campaign:{'.'.join(map(str, path))}={name}", make)
    grid = {"name": "huge", "grid": {f"k{i}": list(range(20)) for i in range(9)}}

    def huge(root: Path, tmp: Path) -> list[str]:
        f = tmp / "campaign.yaml"
        f.write_text(yaml.safe_dump({**CAMPAIGN, "controllers": [{**grid, "name": "dwa-v1"}]}))
        return ["bench", str(f), "--db", str(tmp / "r.sqlite"), "--workers", "1", "--json"]

    yield CliCase("campaign:grid-20^9", huge)
    for name, special in SPECIAL.items():
        yield CliCase(
            f"campaign:file-is-{name}",
            lambda root, tmp, s=special: ["bench", str(s(root)), "--db", str(tmp / "r.sqlite")],
        )


XY4 = "".join(f"{f} {p} {1.0 + 0.05 * f + p} {0.02 * f}\n" for p in (1, 2) for f in range(0, 60, 6))


def _track_cases() -> Iterator[CliCase]:
    def run(path: Path) -> list[str]:
        return ["simulate", "crowd-file:1", "--gen-param", f"path={path}",
                "--gen-param", "format=xy4", "--gen-param", "frame_rate=10",
                "--gen-param", "t_max=1", "-c", "straight-v1", "--json"]  # fmt: skip

    for column, what in enumerate(("frame", "person", "x", "y")):
        for name, token in TEXT_NUMBERS.items():

            def make(root: Path, tmp: Path, column: int = column, token: str = token) -> list:
                rows = [ln.split() for ln in XY4.splitlines()]
                rows[3][column] = token
                f = tmp / "tracks.txt"
                f.write_text("\n".join(" ".join(r) for r in rows) + "\n")
                return run(f)

            yield CliCase(f"track:{what}={name}", make)
    for name, special in SPECIAL.items():
        yield CliCase(f"track:file-is-{name}", lambda root, tmp, s=special: run(s(root)))
    for name, data in (("non-utf8", b"\xff\xfe 1 2 3\n"), ("corrupt-gz", b"\x1f\x8b\x08garbage")):

        def make_bytes(root: Path, tmp: Path, data: bytes = data) -> list[str]:
            f = tmp / ("tracks.txt.gz" if b"\x1f\x8b" in data else "tracks.txt")
            f.write_bytes(data)
            return run(f)

        yield CliCase(f"track:{name}", make_bytes)
    for name, special in SPECIAL.items():

        def in_scene(root: Path, tmp: Path, s: Any = special) -> list[str]:
            scene = {**SCENE, "crowd": {"dataset": str(s(root)), "format": "xy4"}}
            f = tmp / "scene.yaml"
            f.write_text(yaml.safe_dump(scene, sort_keys=False))
            return ["simulate", str(f), "--json"]

        yield CliCase(f"scene:crowd.dataset-is-{name}", in_scene)


def _recon(dem: Path, tmp: Path) -> list[str]:
    options = ["--cell", "10", "--area", "60", "--radius", "15", "--r-min", "5"]
    options += ["--uavs", "1", "--no-figures", "--json"]
    return ["recon", "plan", "--dem", str(dem), *options, "--out", str(tmp / "plan")]


def _forged_npy(shape: tuple[int, ...]) -> bytes:
    import io

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buf, {"descr": "<f8", "fortran_order": False, "shape": shape}
    )
    return buf.getvalue() + bytes(64)


def _dem_cases() -> Iterator[CliCase]:
    def flat() -> np.ndarray:
        return np.random.default_rng(0).random((12, 12)) * 5.0

    for name, value in ARRAY_NUMBERS.items():

        def cell(root: Path, tmp: Path, value: float = value) -> list[str]:
            z = flat()
            z[4, 5] = value
            np.save(tmp / "dem.npy", z)
            return _recon(tmp / "dem.npy", tmp)

        yield CliCase(f"dem:npy-cell={name}", cell)
        for key in ("dx", "x0", "y0"):

            def npz(root: Path, tmp: Path, key: str = key, value: float = value) -> list[str]:
                np.savez(tmp / "dem.npz", z=flat(), **{key: np.float64(value)})
                return _recon(tmp / "dem.npz", tmp)

            yield CliCase(f"dem:npz-{key}={name}", npz)
    arrays = {
        "complex": lambda: flat().astype(complex),
        "strings": lambda: np.array([["a", "b"], ["c", "d"]]),
        "bool": lambda: flat() > 2,
        "1x1": lambda: np.zeros((1, 1)),
        "3d": lambda: np.zeros((4, 4, 4)),
        "empty": lambda: np.zeros((0, 0)),
        "scalar": lambda: np.float64(3.0),
    }
    for name, make_array in arrays.items():

        def shaped(root: Path, tmp: Path, make_array: Any = make_array) -> list[str]:
            np.save(tmp / "dem.npy", make_array())
            return _recon(tmp / "dem.npy", tmp)

        yield CliCase(f"dem:npy-{name}", shaped)
    for name, shape in (("1e6x1e6", (10**6, 10**6)), ("1e4x1e4-truncated", (10**4, 10**4))):

        def forged(root: Path, tmp: Path, shape: Any = shape) -> list[str]:
            (tmp / "dem.npy").write_bytes(_forged_npy(shape))
            return _recon(tmp / "dem.npy", tmp)

        yield CliCase(f"dem:forged-header-{name}", forged)
    for name, special in SPECIAL.items():
        yield CliCase(f"dem:file-is-{name}", lambda root, tmp, s=special: _recon(s(root), tmp))

    def tif_without_crs(root: Path, tmp: Path) -> list[str]:
        rasterio = pytest.importorskip("rasterio")
        profile = {"driver": "GTiff", "height": 12, "width": 12, "count": 1, "dtype": "float32"}
        t = rasterio.Affine(10.0, 0.0, 0.0, 0.0, -10.0, 120.0)
        with rasterio.open(tmp / "dem.tif", "w", transform=t, **profile) as ds:
            ds.write(flat().astype(np.float32), 1)
        return _recon(tmp / "dem.tif", tmp)

    yield CliCase("dem:geotiff-without-crs", tif_without_crs)
    yield CliCase(
        "recon:out-is-a-file",
        lambda root, tmp: ["recon", "plan", "--synthetic", "1", "--out", str(root / "binary")],
    )


def _sonar_arrays(n: int = 12) -> dict[str, np.ndarray]:
    ranges = np.linspace(1.0, 4.0, 9 * n).reshape(n, 9)
    return {
        "ranges": ranges,
        "inputs": ranges.copy(),
        "target_distance": ranges.min(axis=1) - 0.05,
        "target_index": ranges.argmin(axis=1) + 1,
        "baseline_distance": ranges.min(axis=1),
        "baseline_index": ranges.argmin(axis=1) + 1,
    }


@pytest.fixture(scope="module")
def sonar_model(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("sonar")
    np.savez(root / "data.npz", **_sonar_arrays())
    result = runner.invoke(
        app, ["sonar", "train", str(root / "data.npz"), "--out", str(root / "bp"),
              "--max-epochs", "2", "--json"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    return root / "bp"


def _sonar_cases() -> Iterator[CliCase]:
    def evaluate(data: Path) -> list[str]:
        return ["sonar", "evaluate", "@MODEL@", str(data), "--json"]

    for array in ("ranges", "inputs", "target_distance", "target_index"):
        for name, value in ARRAY_NUMBERS.items():

            def make(root: Path, tmp: Path, array: str = array, value: float = value) -> list:
                arrays = _sonar_arrays()
                arrays[array] = arrays[array].astype(float)
                arrays[array][3] = value
                np.savez(tmp / "data.npz", **arrays)
                return evaluate(tmp / "data.npz")

            yield CliCase(f"sonar:{array}={name}", make)

    def empty(root: Path, tmp: Path) -> list[str]:
        np.savez(tmp / "data.npz", **{k: v[:0] for k, v in _sonar_arrays().items()})
        return evaluate(tmp / "data.npz")

    yield CliCase("sonar:empty-arrays", empty)

    def forged(root: Path, tmp: Path) -> list[str]:
        import zipfile

        with zipfile.ZipFile(tmp / "data.npz", "w") as zf:
            zf.writestr("ranges.npy", _forged_npy((10**6, 10**6)))
        return evaluate(tmp / "data.npz")

    yield CliCase("sonar:forged-header", forged)
    for name, special in SPECIAL.items():
        yield CliCase(f"sonar:file-is-{name}", lambda root, tmp, s=special: evaluate(s(root)))


ALL_CLI: list[CliCase] = [
    *_scene_cases(),
    *_param_cases(),
    *_gen_param_cases(),
    *_campaign_cases(),
    *_track_cases(),
    *_dem_cases(),
    *_sonar_cases(),
]


@pytest.mark.parametrize("case", ALL_CLI, ids=[c.id for c in ALL_CLI])
def test_hostile_cli_input(case: CliCase, base: Path, tmp_path: Path, request: Any) -> None:
    argv = case.make(base, tmp_path)
    if "@MODEL@" in argv:
        model = request.getfixturevalue("sonar_model")
        argv = [str(model) if a == "@MODEL@" else a for a in argv]
    result = within_deadline(lambda: runner.invoke(app, argv))
    check_cli(result, as_json=case.as_json)


# ------------------------------------------------------------------------- driving logs (torch)


def _driving_cases() -> Iterator[CliCase]:
    def log(root: Path, tmp: Path, row: list[str]) -> list[str]:
        from PIL import Image

        data = tmp / "drive"
        (data / "IMG").mkdir(parents=True)
        img = Image.new("RGB", (200, 66), (90, 90, 90))
        lines = []
        for k in range(4):
            names = [f"IMG/{cam}_{k}.jpg" for cam in ("center", "left", "right")]
            for n in names:
                img.save(data / n)
            values = row if k == 2 else ["0.1", "0.3", "0", "5"]
            lines.append(",".join([*names, *values]))
        (data / "driving_log.csv").write_text("\n".join(lines) + "\n")
        return ["drive", "train", str(data), "--epochs", "1", "--batch-size", "4",
                "--max-per-bin", "0", "--out", str(tmp / "m.safetensors")]  # fmt: skip

    for column, what in enumerate(("steering", "throttle", "brake", "speed")):
        for name, token in TEXT_NUMBERS.items():
            row = ["0.1", "0.3", "0", "5"]
            row[column] = token
            yield CliCase(
                f"drive:{what}={name}", lambda root, tmp, row=row: log(root, tmp, row), False
            )

    def image(root: Path, tmp: Path, special: Any) -> list[str]:
        argv = log(root, tmp, ["0.1", "0.3", "0", "5"])
        target = tmp / "drive" / "IMG" / "center_1.jpg"
        target.unlink()
        source = special(root)
        if source.exists() and source.is_file() and not source.is_symlink():
            target.write_bytes(source.read_bytes())
        else:
            target.symlink_to(source)
        return argv

    for name, special in SPECIAL.items():
        if name not in ("long-name",):
            yield CliCase(
                f"drive:image-is-{name}", lambda root, tmp, s=special: image(root, tmp, s), False
            )


DRIVING = list(_driving_cases())


@pytest.mark.slow
@pytest.mark.parametrize("case", DRIVING, ids=[c.id for c in DRIVING])
def test_hostile_driving_log(case: CliCase, base: Path, tmp_path: Path) -> None:
    pytest.importorskip("torch")
    result = within_deadline(lambda: runner.invoke(app, case.make(base, tmp_path)))
    check_cli(result, as_json=False)


# ------------------------------------------------------------------------------------ the envs


def _step_zero(env: Any) -> Any:
    obs, _ = env.reset(seed=0)
    out = env.step(np.zeros(env.action_space.shape))
    return obs, out[0], out[1]


def _env_cases() -> Iterator[EnvCase]:
    from uvnav.envs.multi_robot import MultiNav2DParallelEnv
    from uvnav.envs.nav2d import Nav2DEnv
    from uvnav.envs.nav2d_vec import Nav2DVectorEnv
    from uvnav.envs.nav3d import Nav3DEnv
    from uvnav.envs.uuv2d import Uuv2DEnv
    from uvnav.scenarios import load_scenario

    scene = load_scenario("thesis-ch2-one-obstacle")
    nav2d_args = ("n_rays", "max_range", "goal_scale", "raw_commands", "vehicle", "render_mode")
    for arg in (*nav2d_args, "scenario"):
        for name, value in PY_VALUES.items():
            kw = {"scenario": scene, arg: value}
            yield EnvCase(f"env:Nav2D({arg}={name})", lambda kw=kw: _step_zero(Nav2DEnv(**kw)))
    for weight in ("progress", "time", "clearance", "clearance_margin", "success", "collision"):
        for name, value in PY_VALUES.items():
            kw = {"scenario": scene, "reward": {weight: value}}
            yield EnvCase(
                f"env:Nav2D(reward.{weight}={name})", lambda kw=kw: _step_zero(Nav2DEnv(**kw))
            )
    for name, value in PY_VALUES.items():

        def vec(value: Any = value) -> Any:
            env = Nav2DVectorEnv(value, scene, n_rays=4)
            obs, _ = env.reset(seed=0)
            return obs, env.step(np.zeros((env.num_envs, 2)))[:2]

        yield EnvCase(f"env:Nav2DVector(num_envs={name})", vec)
        yield EnvCase(
            f"env:Nav3D(n_obstacles={name})",
            lambda value=value: Nav3DEnv(n_obstacles=value).observation_space.shape,
        )
        yield EnvCase(
            f"env:UUV2D(goal_scale={name})",
            lambda value=value: _step_zero(Uuv2DEnv(goal_scale=value)),
        )
        yield EnvCase(
            f"env:MultiNav2D(n_rays={name})",
            lambda value=value: MultiNav2DParallelEnv("antipodal:2", n_rays=value).reset(seed=0),
        )
        yield EnvCase(
            f"env:Nav2D.reset(episode_seed={name})",
            lambda value=value: Nav2DEnv(scene).reset(options={"episode_seed": value}),
        )


ACTIONS: dict[str, Any] = {
    "nan": [math.nan, 0.0],
    "inf": [math.inf, 0.0],
    "-inf": [0.0, -math.inf],
    "1e300": [1e300, 0.0],
    "1e15": [1e15, 1e15],
    "-1": [-1.0, -1.0],
    "0": [0.0, 0.0],
    "2.5": [2.5, -2.5],
    "10^400": [10**400, 0],
    "empty": "",
    "long-string": "x" * 5000,
    "nested": [[0.0, 0.0]],
    "mapping": {"a": 1},
    "none": None,
    "bool": True,
    "bytes": b"\xff\xfe",
    "three": [0.0, 0.0, 0.0],
}


def _action_cases() -> Iterator[EnvCase]:
    from uvnav.envs.multi_robot import MultiNav2DParallelEnv
    from uvnav.envs.nav2d import Nav2DEnv
    from uvnav.envs.nav2d_vec import Nav2DVectorEnv
    from uvnav.envs.nav3d import Nav3DEnv
    from uvnav.envs.uuv2d import Uuv2DEnv

    def single(make: Callable[[], Any], value: Any) -> Any:
        env = make()
        env.reset(seed=0)
        if isinstance(value, list) and len(value) == 2 and env.action_space.shape == (3,):
            value = [*value, 0.0]
        out = env.step(value)
        return out[0], out[1]

    def vector(value: Any) -> Any:
        env = Nav2DVectorEnv(2, "thesis-ch2-one-obstacle", n_rays=4)
        env.reset(seed=0)
        actions = value if not isinstance(value, list) else [value, [0.0, 0.0]]
        return env.step(actions)[:2]

    def multi(value: Any) -> Any:
        env = MultiNav2DParallelEnv("antipodal:2", n_rays=4)
        env.reset(seed=0)
        out = env.step({a: value for a in env.agents})
        return out[0], out[1]

    makers: dict[str, Callable[[Any], Any]] = {
        "Nav2D": lambda v: single(lambda: Nav2DEnv(n_rays=4), v),
        "Nav2D-raw": lambda v: single(lambda: Nav2DEnv(n_rays=4, raw_commands=True), v),
        "Nav2D-holonomic": lambda v: single(lambda: Nav2DEnv(n_rays=4, vehicle="holonomic"), v),
        "Nav3D": lambda v: single(Nav3DEnv, v),
        "UUV2D": lambda v: single(Uuv2DEnv, v),
        "Nav2DVector": vector,
        "MultiNav2D": multi,
    }
    for env_name, run in makers.items():
        for name, value in ACTIONS.items():
            yield EnvCase(f"action:{env_name}={name}", lambda run=run, value=value: run(value))


ALL_ENV: list[EnvCase] = (
    [*_env_cases(), *_action_cases()] if importlib.util.find_spec("gymnasium") else []
)


@pytest.mark.parametrize("case", ALL_ENV, ids=[c.id for c in ALL_ENV])
def test_hostile_env_input(case: EnvCase) -> None:
    within_deadline(lambda: check_env(case.run))


def test_the_corpus_covers_every_surface_with_enough_cases() -> None:
    surfaces = {c.id.split(":")[0] for c in [*ALL_CLI, *DRIVING, *ALL_ENV]}
    assert surfaces >= {"scene", "param", "gen-param", "campaign", "track", "dem", "sonar",
                        "drive", "env", "action", "recon"}  # fmt: skip
    assert len(ALL_CLI) + len(DRIVING) + len(ALL_ENV) >= 650
