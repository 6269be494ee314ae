"""Malformed-input corpus (issue 17, items 1-3): every command, every file type, every field.

Variants are generated from VALID inputs (shipped scenario and campaign files, small files written
by uvnav itself): for each numeric field of a YAML file, NaN / inf / a wrong type (and, where the
field must be positive, a negative value; where it bounds the run, a huge one); for binary files,
NaN/inf cells, wrong dtypes and shapes, missing keys; for every file, an empty file, binary
garbage, a truncated copy and a directory in its place; and bad command-line options.

Every case must end with exit status 2 and exactly ONE output line ``error: ...`` that names the
file (or the option) and the field, and no traceback.  The cases run in-process through Typer's
``CliRunner`` and fail before any episode, training or planning starts, so the whole corpus runs
in seconds; the inputs that need torch (checkpoints, driving logs) are marked ``slow``.

Variants that may legitimately be accepted (a negative coordinate, a missing field with a default)
are in :func:`test_tolerated_variants_never_trace_back`: either OK or one ``error:`` line.
"""

from __future__ import annotations

import copy
import json
import math
import sqlite3
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from cli_runner import FastRunner
from uvnav.cli.app import app

runner = FastRunner()

ROOT = Path(__file__).resolve().parents[2]
BUILTIN = ROOT / "src" / "uvnav" / "scenarios" / "builtin"
CAMPAIGNS = ROOT / "campaigns"

# ------------------------------------------------------------------------------------- the check


def _check(result: Any, must_name: tuple[str, ...]) -> str:
    out = result.output
    assert "Traceback" not in out, out
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(
        result.exception
    )
    lines = [ln for ln in out.splitlines() if ln.strip()]
    assert len(lines) == 1, f"expected one line, got:\n{out}"
    line = lines[0]
    assert line.startswith("error:"), line
    assert result.exit_code == 2, f"exit {result.exit_code}: {line}"
    for word in must_name:
        if not word:
            continue
        assert word in line, f"{word!r} not named in: {line}"
    return line


@dataclass
class Case:
    """One malformed input: ``make(dir) -> (argv, words the error line must name)``."""

    id: str
    make: Callable[..., tuple[list[str], tuple[str, ...]]]
    marks: tuple[Any, ...] = field(default_factory=tuple)


# ------------------------------------------------------------------------------ YAML mutation


def _leaves(node: Any, path: tuple[Any, ...] = ()) -> Iterator[tuple[tuple[Any, ...], Any]]:
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _leaves(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _leaves(v, (*path, i))
    else:
        yield path, node


def _set(data: Any, path: tuple[Any, ...], value: Any) -> Any:
    out = copy.deepcopy(data)
    node = out
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    return out


def _delete(data: Any, path: tuple[Any, ...]) -> Any:
    out = copy.deepcopy(data)
    node = out
    for p in path[:-1]:
        node = node[p]
    del node[path[-1]]
    return out


#: fields that must be > 0 (or >= 0): a negative value is an error wherever they appear
POSITIVE = {
    "dt",
    "control_period",
    "t_max",
    "goal_tolerance",
    "v_max",
    "u_max",
    "radius",
    "range",
    "max_range",
    "base_radius",
    "slot_width",
    "arm_length",
    "arm_thickness",
    "height",
    "area",
    "max_rate",
    "n_beams",
    "fov",
    "switch_distance",
    "noise_std",
    "position_noise",
    "change_period",
    "half_angle_deg",
    "ring_angle_deg",
    "delta_max",
    "max_frequency",
    "frequency",
    "shape_scale",
    "shape_seed",
    "seed",
    "sharpness",
    "deadlock_window",
    "deadlock_distance",
}
#: fields whose huge value makes an unbounded run or a mismatch with another field
HUGE_FAILS = {"dt", "t_max"}
NAN, INF, HUGE = float("nan"), float("inf"), 1e300


def _field_name(path: tuple[Any, ...]) -> str:
    """The field the error must name; ``dim`` decides the file's kind, so a bad ``dim`` reads
    as another kind's scene and the error names the first field that kind refuses: the file is
    named, nothing more is required."""
    name = next(str(p) for p in reversed(path) if isinstance(p, str))
    return "" if name == "dim" else name


def _yaml_variants(data: Any) -> Iterator[tuple[str, Any, str, bool]]:
    """``(id, mutated data, field name, must fail)`` for each numeric leaf of ``data``."""
    for path, value in _leaves(data):
        if isinstance(value, bool) or not isinstance(value, int | float):
            continue
        dotted = ".".join(str(p) for p in path)
        name = _field_name(path)
        if "params" in path:  # law parameters are checked by the law, not the schema
            continue
        if any(isinstance(p, int) and p > 0 for p in path):  # one item of each list is enough
            continue
        yield f"{dotted}=nan", _set(data, path, NAN), name, True
        yield f"{dotted}=inf", _set(data, path, INF), name, True
        yield f"{dotted}=str", _set(data, path, "abc"), name, True
        positive = name in POSITIVE and path[-1] == name
        yield f"{dotted}=-1", _set(data, path, -1.5), name, positive
        yield f"{dotted}=huge", _set(data, path, HUGE), name, name in HUGE_FAILS
        yield f"{dotted}=missing", _delete(data, path), name, False


_Dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


def _dump(data: Any) -> str:
    # NaN/inf as YAML's .nan/.inf (what a user writes)
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True)


def _file_variants(text: str) -> Iterator[tuple[str, Callable[[Path], None]]]:
    """Whole-file breakage: empty, binary garbage, truncated, a directory, YAML junk."""

    def writer(content: bytes) -> Callable[[Path], None]:
        return lambda p: p.write_bytes(content)

    def directory(p: Path) -> None:
        p.mkdir()

    raw = text.encode()
    yield "empty", writer(b"")
    yield "binary", writer(bytes(range(256)) * 4)
    yield "binary-utf8-prefix", writer(b"name: x\n" + bytes(range(128, 256)))
    yield "truncated-half", writer(raw[: len(raw) // 2])
    yield "truncated-third", writer(raw[: len(raw) // 3])
    yield "directory", directory
    yield "yaml-list", writer(b"- 1\n- 2\n")
    yield "yaml-scalar", writer(b"42\n")
    yield "yaml-syntax", writer(b"name: [unclosed\n")
    yield "tab-indent", writer(b"name: x\nrobot:\n\tv_max: 1\n")


# ----------------------------------------------------------------------------- scenario files

SCENES = {
    "nav2d": BUILTIN / "thesis-ch2-one-obstacle.yaml",
    "nav3d": BUILTIN / "thesis-ch3-fig3-5-single-cycle.yaml",
    "uuv2d": BUILTIN / "ch4" / "thesis-ch4-fig4-7-approach.yaml",
    "uuv3d": BUILTIN / "ch5" / "thesis-ch5-scene1.yaml",
    "uuv3d-horseshoe": BUILTIN / "ch5" / "thesis-ch5-scene2.yaml",
}

MULTI = {
    "name": "two-robots",
    "dt": 0.1,
    "control_period": 0.1,
    "t_max": 20.0,
    "goal_tolerance": 0.2,
    "robots": [
        {"name": "a", "start": [0.0, 0.0], "goal": [6.0, 0.0], "v_max": 1.0, "u_max": 2.0,
         "radius": 0.2},
        {"name": "b", "start": [6.0, 1.0], "goal": [0.0, 1.0], "v_max": 1.0, "u_max": 2.0,
         "radius": 0.2},
    ],
    "obstacles": [],
    "controller": {"name": "zhang2019-v1"},
}  # fmt: skip


def _scene_data() -> dict[str, Any]:
    out = {k: yaml.safe_load(p.read_text()) for k, p in SCENES.items()}
    out["multi2d"] = MULTI
    return out


def _scene_cases() -> tuple[list[Case], list[Case]]:
    must: list[Case] = []
    tolerated: list[Case] = []
    for kind, data in _scene_data().items():
        for vid, variant, name, fails in _yaml_variants(data):

            def make(d: Path, variant: Any = variant, name: str = name) -> Any:
                f = d / "scene.yaml"
                f.write_text(_dump(variant))
                return ["scenarios", "validate", str(f)], (str(f), name)

            (must if fails else tolerated).append(Case(f"validate-{kind}-{vid}", make))
            if fails and vid.endswith("=nan"):

                def make_sim(d: Path, variant: Any = variant, name: str = name) -> Any:
                    f = d / "scene.yaml"
                    f.write_text(_dump(variant))
                    return ["simulate", str(f)], (str(f), name)

                must.append(Case(f"simulate-{kind}-{vid}", make_sim))
        text = _dump(data)
        for vid, write in _file_variants(text):
            for cmd in (["scenarios", "validate"], ["simulate"]):

                def make_file(d: Path, write: Any = write, cmd: list[str] = cmd) -> Any:
                    f = d / "scene.yaml"
                    write(f)
                    return [*cmd, str(f)], (str(f),)

                must.append(Case(f"{cmd[-1]}-{kind}-file-{vid}", make_file))
    return must, tolerated


def _ch5(**robot: Any) -> dict[str, Any]:
    data = yaml.safe_load(SCENES["uuv3d"].read_text())
    data["robot"].update(robot)
    return data


def _scene_semantic_cases() -> list[Case]:
    """Accepted-but-wrong scenes (issue 17): must be refused with the field named."""
    ch5 = yaml.safe_load(SCENES["uuv3d"].read_text())
    centre = ch5["obstacles"][0]["centre"]
    specs: dict[str, tuple[dict[str, Any], str]] = {
        "ch5-goal-inside-body": (_ch5(goal=list(centre)), "robot.goal"),
        "ch5-start-inside-body": (_ch5(start=list(centre)), "robot.start"),
        "ch5-start-overlaps-body": (
            _ch5(start=[centre[0] - 2.6, centre[1], centre[2]]),
            "robot.start",
        ),
        "ch5-control-period-not-multiple": ({**ch5, "control_period": 0.13}, "control_period"),
        "ch5-dt-tiny": ({**ch5, "dt": 1e-6}, "dt"),
        "ch5-dt-above-control-period": ({**ch5, "dt": 1.0}, "control_period"),
        "ch5-start-equals-goal": (_ch5(goal=[0, 0, 0]), "robot.goal"),
        "ch5-heading-zero": (_ch5(heading=[0, 0, 0]), "heading"),
        "ch5-heading-nan": (_ch5(heading=[NAN, 1, 0]), "heading"),
        "ch5-sonar-range-inf": ({**ch5, "sonar": {"max_range": INF}}, "max_range"),
    }
    for kind in ("nav2d", "nav3d", "uuv2d"):
        base = yaml.safe_load(SCENES[kind].read_text())
        specs[f"{kind}-dt-tiny"] = ({**base, "dt": 1e-6, "control_period": 1e-6}, "dt")
        specs[f"{kind}-t-max-huge"] = ({**base, "t_max": 1e12}, "t_max")
        specs[f"{kind}-control-period-not-multiple"] = (
            {**base, "control_period": base["dt"] * 1.5},
            "control_period",
        )
    multi = copy.deepcopy(MULTI)
    specs["multi2d-dt-tiny"] = ({**multi, "dt": 1e-6, "control_period": 1e-6}, "dt")
    specs["multi2d-t-max-huge"] = ({**multi, "t_max": 1e12}, "t_max")
    specs["multi2d-robots-empty"] = ({**multi, "robots": []}, "robots")
    specs["multi2d-robots-not-list"] = ({**multi, "robots": 3}, "robots")
    cases = []
    for cid, (data, name) in specs.items():
        text = _dump(data)
        for cmd in (["scenarios", "validate"], ["simulate"]):

            def make(d: Path, text: str = text, name: str = name, cmd: list[str] = cmd) -> Any:
                f = d / "scene.yaml"
                f.write_text(text)
                return [*cmd, str(f)], (str(f), name)

            cases.append(Case(f"{cmd[-1]}-{cid}", make))
    return cases


# ---------------------------------------------------------------------------- pedestrian files

PEDS = "\n".join(
    f"{frame} {pid} {x:.2f} {y:.2f}"
    for frame in range(0, 60, 6)
    for pid, (x, y) in enumerate([(1.0 + frame / 20, 2.0), (4.0, 1.0 + frame / 30)], start=1)
)


def _crowd_scene(d: Path) -> Path:
    data = yaml.safe_load(SCENES["nav2d"].read_text())
    data["obstacles"] = []
    data["crowd"] = {"dataset": "peds.txt", "format": "xy4", "t_start": 0.0, "frame_rate": 15.0}
    f = d / "crowd.yaml"
    f.write_text(_dump(data))
    return f


def _pedestrian_cases() -> list[Case]:
    cases = []
    lines = PEDS.splitlines()
    for row in (0, 3, len(lines) - 1):
        for col in range(4):
            for bad in ("nan", "inf", "abc", "DROP"):
                parts = lines[row].split()
                if bad == "DROP":
                    del parts[col]
                else:
                    parts[col] = bad
                text = "\n".join([*lines[:row], " ".join(parts), *lines[row + 1 :]])

                def make(d: Path, text: str = text, row: int = row) -> Any:
                    (d / "peds.txt").write_text(text)
                    f = _crowd_scene(d)
                    return ["scenarios", "validate", str(f)], ("peds.txt", f"line {row + 1}")

                cases.append(Case(f"peds-r{row}c{col}-{bad}", make))
    for vid, write in _file_variants(PEDS):
        if vid.startswith(("yaml", "tab", "truncated")):
            continue

        def make_file(d: Path, write: Any = write) -> Any:
            write(d / "peds.txt")
            f = _crowd_scene(d)
            return ["scenarios", "validate", str(f)], ("peds.txt", "crowd.dataset")

        cases.append(Case(f"peds-file-{vid}", make_file))
    for key, value in (("frame_rate", NAN), ("frame_rate", -1.0), ("radius", INF)):

        def make_opt(d: Path, key: str = key, value: float = value) -> Any:
            (d / "peds.txt").write_text(PEDS)
            f = _crowd_scene(d)
            data = yaml.safe_load(f.read_text())
            data["crowd"][key] = value
            f.write_text(_dump(data))
            return ["scenarios", "validate", str(f)], (str(f), key)

        cases.append(Case(f"peds-crowd-{key}-{value}", make_opt))
    return cases


# -------------------------------------------------------------------------------- campaigns


def _campaign_cases() -> list[Case]:
    data = yaml.safe_load((CAMPAIGNS / "ch2-and-crowds.yaml").read_text())
    data["scenarios"] = data["scenarios"][:2]
    cases = []
    for vid, variant, name, fails in _yaml_variants(data):
        if not fails:
            continue

        def make(d: Path, variant: Any = variant, name: str = name) -> Any:
            f = d / "camp.yaml"
            f.write_text(_dump(variant))
            return ["bench", str(f), "--db", str(d / "db.sqlite")], (str(f), name)

        cases.append(Case(f"bench-{vid}", make))
    specials: dict[str, tuple[Any, str]] = {
        "seeds-huge": ([0, 1e12], "seeds"),
        "seeds-reversed": ([10, 0], "seeds"),
        "seeds-negative": ([-5, 3], "seeds"),
        "seeds-float": ([0.5, 3], "seeds"),
        "seeds-str": ("many", "seeds"),
    }
    for cid, (seeds, name) in specials.items():
        variant = copy.deepcopy(data)
        variant["scenarios"][0]["seeds"] = seeds
        cases.append(_campaign_case(cid, variant, name))
    for cid, params, name in (
        ("n-obstacles-negative", {"n_obstacles": -3}, "n_obstacles"),
        ("n-obstacles-nan", {"n_obstacles": NAN}, "n_obstacles"),
        ("t-max-str", {"t_max": "long"}, "t_max"),
        ("v-max-nan", {"v_max": NAN}, "v_max"),
        ("v-max-negative", {"v_max": -1.0}, "v_max"),
    ):
        variant = copy.deepcopy(data)
        variant["scenarios"][0]["params"] = params
        cases.append(_campaign_case(f"params-{cid}", variant, name))
    for vid, write in _file_variants(_dump(data)):

        def make_file(d: Path, write: Any = write) -> Any:
            f = d / "camp.yaml"
            write(f)
            return ["bench", str(f), "--db", str(d / "db.sqlite")], (str(f),)

        cases.append(Case(f"bench-file-{vid}", make_file))
    return cases


def _campaign_case(cid: str, data: Any, name: str) -> Case:
    text = _dump(data)

    def make(d: Path) -> Any:
        f = d / "camp.yaml"
        f.write_text(text)
        return ["bench", str(f), "--db", str(d / "db.sqlite")], (str(f), name)

    return Case(f"bench-{cid}", make)


# -------------------------------------------------------------------------------- databases


def _small_campaign(d: Path) -> Path:
    f = d / "camp.yaml"
    f.write_text(
        "name: tiny\nscenarios:\n  - builtin: thesis-ch2-one-obstacle\n    seeds: [0, 1]\n"
        "controllers:\n  - name: straight-v1\n"
    )
    return f


def _db_variants() -> Iterator[tuple[str, Callable[[Path], None]]]:
    def writer(content: bytes) -> Callable[[Path], None]:
        return lambda p: p.write_bytes(content)

    def directory(p: Path) -> None:
        p.mkdir()

    def foreign(p: Path) -> None:
        con = sqlite3.connect(p)
        con.execute("CREATE TABLE t (a INTEGER)")
        con.commit()
        con.close()

    def truncated(p: Path) -> None:
        foreign(p)
        raw = p.read_bytes()
        p.write_bytes(raw[:100])

    def bad_header(p: Path) -> None:
        p.write_bytes(b"SQLite format 3\x00" + bytes(range(256)) * 8)

    yield "empty", writer(b"")
    yield "garbage", writer(bytes(range(256)) * 16)
    yield "text", writer(b"hello, I am not a database\n")
    yield "directory", directory
    yield "foreign-sqlite", foreign
    yield "truncated-sqlite", truncated
    yield "corrupt-sqlite-header", bad_header


def _database_cases() -> list[Case]:
    cases = []
    for vid, write in _db_variants():

        def make_report(d: Path, write: Any = write) -> Any:
            db = d / "results.sqlite"
            write(db)
            return ["report", str(db), "--out", str(d / "report")], (str(db),)

        def make_bench(d: Path, write: Any = write) -> Any:
            db = d / "results.sqlite"
            write(db)
            return ["bench", str(_small_campaign(d)), "--db", str(db)], (str(db),)

        cases.append(Case(f"report-db-{vid}", make_report))
        if vid != "empty":  # an empty file is a fresh database for bench
            cases.append(Case(f"bench-db-{vid}", make_bench))
    return cases


# ------------------------------------------------------------------------------------- DEMs


def _dem_cases() -> list[Case]:
    z = np.random.default_rng(0).uniform(0.0, 20.0, size=(40, 40))
    arrays: dict[str, Callable[[Path], None]] = {
        "nan-cell.npy": lambda p: np.save(p, np.where(np.eye(40, dtype=bool), NAN, z)),
        "inf-cell.npy": lambda p: np.save(p, np.where(np.eye(40, dtype=bool), INF, z)),
        "one-d.npy": lambda p: np.save(p, z[0]),
        "three-d.npy": lambda p: np.save(p, z[None]),
        "one-by-one.npy": lambda p: np.save(p, z[:1, :1]),
        "strings.npy": lambda p: np.save(p, np.array([["a", "b"], ["c", "d"]])),
        "pickle.npy": lambda p: np.save(p, np.array([{"a": 1}], dtype=object), allow_pickle=True),
        "complex.npy": lambda p: np.save(p, z.astype(complex) * 1j),
        "no-z.npz": lambda p: np.savez(p, heights=z),
        "dx-nan.npz": lambda p: np.savez(p, z=z, dx=NAN),
        "dx-zero.npz": lambda p: np.savez(p, z=z, dx=0.0),
        "dx-negative.npz": lambda p: np.savez(p, z=z, dx=-5.0),
        "dx-inf.npz": lambda p: np.savez(p, z=z, dx=INF),
        "dx-array.npz": lambda p: np.savez(p, z=z, dx=np.ones(3)),
        "x0-nan.npz": lambda p: np.savez(p, z=z, x0=NAN),
        "x0-str.npz": lambda p: np.savez(p, z=z, x0="west"),
        "z-nan.npz": lambda p: np.savez(p, z=np.full((40, 40), NAN)),
    }

    def raw(content: bytes) -> Callable[[Path], None]:
        return lambda p: p.write_bytes(content)

    def truncated_tif(p: Path) -> None:
        _write_tif(p, z)
        p.write_bytes(p.read_bytes()[:300])

    def directory(p: Path) -> None:
        p.mkdir()

    files: dict[str, Callable[[Path], None]] = {
        **arrays,
        "garbage.tif": raw(bytes(range(256)) * 8),
        "empty.tif": raw(b""),
        "text.tif": raw(b"not a tiff\n"),
        "truncated.tif": truncated_tif,
        "garbage.npy": raw(bytes(range(256)) * 8),
        "empty.npy": raw(b""),
        "garbage.npz": raw(bytes(range(256)) * 8),
        "empty.npz": raw(b""),
        "truncated.npz": lambda p: (np.savez(p, z=z), p.write_bytes(p.read_bytes()[:200])),
        "unknown.xyz": raw(b"1 2 3\n"),
        "dir.tif": directory,
    }
    cases = []
    for name, write in files.items():

        def make(d: Path, name: str = name, write: Any = write) -> Any:
            f = d / name
            write(f)
            return [
                "recon", "plan", "--dem", str(f), "--area", "100", "--cell", "5",
                "--out", str(d / "out"), "--no-figures",
            ], (str(f),)  # fmt: skip

        cases.append(Case(f"dem-{name}", make))
    return cases


def _write_tif(p: Path, z: np.ndarray) -> None:
    import rasterio
    from rasterio.transform import from_origin

    with rasterio.open(
        p, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1, dtype="float64",
        crs="EPSG:32633", transform=from_origin(0, z.shape[0] * 5.0, 5.0, 5.0),
    ) as ds:  # fmt: skip
        ds.write(z, 1)


def _recon_option_cases() -> list[Case]:
    bad: list[tuple[str, str]] = [
        ("--cell", "0"), ("--cell", "-1"), ("--cell", "nan"), ("--cell", "inf"),
        ("--cell", "1e-9"),
        ("--area", "1e9"), ("--area", "0"), ("--area", "-5"), ("--area", "nan"),
        ("--area", "inf"), ("--area", "abc"), ("--area", "1,2,3"), ("--area", "0,0,nan,100"),
        ("--area", "10,10,0,0"), ("--area", "0,0,1e9,1e9"),
        ("--theta", "0"), ("--theta", "180"), ("--theta", "nan"), ("--theta", "-30"),
        ("--radius", "0"), ("--radius", "-1"), ("--radius", "nan"), ("--radius", "inf"),
        ("--uavs", "0"), ("--uavs", "-1"),
        ("--delta", "nan"), ("--delta", "0"), ("--delta", "-1"),
        ("--c1", "nan"), ("--c1", "-1"), ("--c2", "inf"), ("--c2", "-1"),
        ("--r-min", "0"), ("--r-min", "nan"), ("--r-min", "-3"),
        ("--z-min", "nan"), ("--z-max", "inf"), ("--z-max", "-10"),
        ("--seed", "-1"), ("--synthetic", "-1"), ("--synthetic", "abc"),
    ]  # fmt: skip
    cases = []
    for opt, value in bad:

        def make(d: Path, opt: str = opt, value: str = value) -> Any:
            argv = ["recon", "plan", "--out", str(d / "out"), "--no-figures"]
            if opt != "--synthetic":
                argv += ["--synthetic", "0"]
            return [*argv, opt, value], (opt,)

        cases.append(Case(f"recon-opt{opt}={value}", make))
    return cases


# ------------------------------------------------------------------------------ CLI options


def _option_cases() -> list[Case]:
    specs: list[tuple[list[str], str]] = [
        (["simulate", "thesis-ch2-one-obstacle", "--seed", "-1"], "--seed"),
        (["simulate", "thesis-ch2-one-obstacle", "--seed", "abc"], "--seed"),
        (["simulate", "thesis-ch2-one-obstacle", "--seed", "1e3"], "--seed"),
        (["simulate", "thesis-ch2-one-obstacle", "-p", "nonsense"], "--param"),
        (["simulate", "thesis-ch2-one-obstacle", "-p", "alpha0=[unclosed"], "--param"),
        (["simulate", "thesis-ch2-one-obstacle", "-c", "no-such-law"], "no-such-law"),
        (["simulate", "random-ch2:-1"], "seed"),
        (["simulate", "random-ch2:abc"], "seed"),
        (["simulate", "random-ch2:1e3"], "seed"),
        (["simulate", "antipodal:0"], "antipodal"),
        (["simulate", "antipodal:100000"], "antipodal"),
        (["simulate", "no-such-scene"], "no-such-scene"),
        (["scenarios", "validate", "random-ch5:-3"], "seed"),
        (["scenarios", "show", "no-such-scene"], "no-such-scene"),
        (["scenarios", "schema", "--kind", "nav9d"], "--kind"),
        (["controllers", "show", "no-such-law"], "no-such-law"),
        (["controllers", "list", "--vehicle", "boat"], "--vehicle"),
        (["bench", "missing.yaml"], "missing.yaml"),
        (["bench", "missing.yaml", "--workers", "0"], "--workers"),
        (["run", "--workers", "100000"], "--workers"),
        (["reproduce", "ch2", "--workers", "100000"], "--workers"),
        (["bench", "missing.yaml", "--engine", "gpu"], "--engine"),
        (["report", "missing.sqlite"], "missing.sqlite"),
        (["run", "--workers", "0"], "--workers"),
        (["sonar", "dataset", "--samples", "0"], "--samples"),
        (["sonar", "dataset", "--samples", "1000000000"], "--samples"),
        (["sonar", "dataset", "--seed", "-1"], "--seed"),
        (["sonar", "dataset", "--dropout", "2"], "--dropout"),
        (["sonar", "dataset", "--dropout", "nan"], "--dropout"),
        (["sonar", "dataset", "--noise", "-1"], "--noise"),
        (["sonar", "dataset", "--subdivisions", "9"], "--subdivisions"),
        (["simulate", "thesis-ch5-scene1", "-p", "locator=psychic"], "psychic"),
        (["simulate", "thesis-ch5-scene1", "-p", "model=m"], "model"),
        (["sonar", "evaluate", "missing", "missing.npz"], "missing"),
        (["sonar", "train", "missing.npz"], "missing.npz"),
        (["drive", "evaluate", "missing.safetensors"], "missing.safetensors"),
        (["drive", "evaluate", "m.safetensors", "--seeds", "-1"], "--seeds"),
        (["drive", "evaluate", "m.safetensors", "--seeds", "5-2"], "--seeds"),
        (["drive", "evaluate", "m.safetensors", "--seeds", "a-b"], "--seeds"),
        (["drive", "evaluate", "m.safetensors", "--max-steps", "0"], "--max-steps"),
        (["drive", "evaluate", "m.safetensors", "--set-speed", "nan"], "--set-speed"),
        (["drive", "train", "missing-dir"], "missing-dir"),
        (["drive", "collect", "--out", "d", "--camera", "side"], "--camera"),
        (["drive", "collect", "--out", "d", "--episodes", "0"], "--episodes"),
        (["drive", "collect", "--out", "d", "--noise", "nan"], "--noise"),
        (["drive", "play", "m.safetensors", "--out", "x.txt"], "--out"),
        (["sonar", "--help-me"], "--help-me"),
        (["ch4", "simulate"], "ch4"),
    ]
    cases = []
    for argv, word in specs:

        def make(d: Path, argv: list[str] = argv, word: str = word) -> Any:
            return list(argv), (word,)

        cases.append(Case("opt-" + "_".join(argv)[:80], make))
    return cases


# ------------------------------------------------------------------------ sonar datasets


@pytest.fixture(scope="module")
def sonar_files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A valid sonar dataset (.npz) and a BPNN checkpoint trained on it (a few epochs)."""
    d = tmp_path_factory.mktemp("sonar")
    ds = d / "sonar.npz"
    r = runner.invoke(app, ["sonar", "dataset", "--out", str(ds), "--samples", "30",
                            "--subdivisions", "1"])  # fmt: skip
    assert r.exit_code == 0, r.output
    ck = d / "bpnn"
    r = runner.invoke(app, ["sonar", "train", str(ds), "--out", str(ck), "--max-epochs", "3"])
    assert r.exit_code == 0, r.output
    return {"dataset": ds, "checkpoint": ck}


def _sonar_dataset_cases() -> list[Case]:
    cases = []
    floats = ["ranges", "inputs", "target_distance", "baseline_distance"]
    ints = ["target_index", "baseline_index"]
    kinds = ["missing", "strings", "wrong-shape", "empty"]
    combos = [(k, kind) for k in floats for kind in (*kinds, "nan", "inf")]
    combos += [(k, kind) for k in ints for kind in (*kinds, "zero", "ten", "float")]
    for key, kind in combos:

        def make(d: Path, files: dict[str, Path], key: str = key, kind: str = kind) -> Any:
            with np.load(files["dataset"]) as data:
                arrays = {k: data[k] for k in data.files}
            a = arrays.pop(key)
            if kind != "missing":
                b = a.astype(float) if kind in ("nan", "inf", "float") else a.copy()
                value = {"nan": NAN, "inf": INF, "zero": 0, "ten": 10, "float": 2.5}.get(kind)
                if value is not None:
                    b.flat[0] = value
                elif kind == "strings":
                    b = np.full(a.shape, "x")
                elif kind == "wrong-shape":
                    b = a.reshape(-1)[:-1]
                else:
                    b = a[:0]
                arrays[key] = b
            f = d / "bad.npz"
            np.savez(f, **arrays)
            # an empty ``ranges`` makes the other arrays the wrong length: they are named
            named = "" if (key, kind) == ("ranges", "empty") else key
            return ["sonar", "train", str(f), "--max-epochs", "1", "--out",
                    str(d / "ck")], (str(f), named)  # fmt: skip

        cases.append(Case(f"sonar-ds-{key}-{kind}", make))
    for vid, write in _bin_file_variants():

        def make_file(d: Path, files: dict[str, Path], write: Any = write) -> Any:
            f = d / "bad.npz"
            write(f, files["dataset"])
            return ["sonar", "train", str(f), "--out", str(d / "ck")], (str(f),)

        def make_eval(d: Path, files: dict[str, Path], write: Any = write) -> Any:
            f = d / "bad.npz"
            write(f, files["dataset"])
            return ["sonar", "evaluate", str(files["checkpoint"]), str(f)], (str(f),)

        cases.append(Case(f"sonar-train-file-{vid}", make_file))
        cases.append(Case(f"sonar-eval-file-{vid}", make_eval))
    for opt, value in (
        ("--hidden", "0"), ("--hidden", "-3"), ("--hidden", "abc"), ("--hidden", ""),
        ("--hidden", "10,,5"), ("--hidden", "100000000"), ("--optimizer", "sgd"),
        ("--seed", "-1"), ("--max-epochs", "0"),
    ):  # fmt: skip

        def make_opt(d: Path, files: dict[str, Path], opt: str = opt, value: str = value) -> Any:
            return ["sonar", "train", str(files["dataset"]), "--out", str(d / "ck"), opt,
                    value], (opt,)  # fmt: skip

        cases.append(Case(f"sonar-train-opt{opt}={value}", make_opt))
    return cases


def _bin_file_variants() -> Iterator[tuple[str, Callable[[Path, Path], None]]]:
    def raw(content: bytes) -> Callable[[Path, Path], None]:
        return lambda p, src: p.write_bytes(content)

    def truncated(p: Path, src: Path) -> None:
        b = src.read_bytes()
        p.write_bytes(b[: len(b) // 2])

    def directory(p: Path, src: Path) -> None:
        p.mkdir()

    def pickled(p: Path, src: Path) -> None:
        np.savez(p, inputs=np.array([{"evil": 1}], dtype=object))

    yield "empty", raw(b"")
    yield "garbage", raw(bytes(range(256)) * 8)
    yield "text", raw(b"distance,index\n1,2\n")
    yield "truncated", truncated
    yield "directory", directory
    yield "pickle", pickled


# ------------------------------------------------------------------------------ checkpoints


def _bpnn_checkpoint_cases() -> list[Case]:
    cases = []

    def json_mut(fn: Callable[[dict[str, Any]], Any], what: str) -> Callable[..., Any]:
        # the header that counts is the one inside the weights file (the .json is its copy)
        def make(d: Path, files: dict[str, Path]) -> Any:
            from safetensors import safe_open
            from safetensors.numpy import save_file

            src = files["checkpoint"].with_suffix(".safetensors")
            with safe_open(str(src), framework="numpy") as fh:
                tensors = {k: fh.get_tensor(k) for k in fh.keys()}  # noqa: SIM118
                meta = dict(fh.metadata() or {})
            header = json.loads(meta["uvnav"])
            fn(header)
            meta["uvnav"] = json.dumps(header)
            save_file(tensors, str(d / "ck.safetensors"), metadata=meta)
            (d / "ck.json").write_text(json.dumps(header))
            return ["sonar", "evaluate", str(d / "ck"), str(files["dataset"])], ("ck", what)

        return make

    def drop(key: str) -> Callable[[dict[str, Any]], None]:
        return lambda m: m.pop(key, None)

    def put(key: str, value: Any) -> Callable[[dict[str, Any]], None]:
        def f(m: dict[str, Any]) -> None:
            node = m
            *parents, last = key.split(".")
            for p in parents:
                node = node.setdefault(p, {})
            node[last] = value

        return f

    for key, fn in (
        ("format", drop("format")),
        ("format", put("format", "pickle-v0")),
        ("config", drop("config")),
        ("config", put("config", "big")),
        ("hidden", put("config.hidden", "ten")),
        ("hidden", put("config.hidden", [-1])),
        ("hidden", put("config.hidden", [4000000])),
    ):
        cases.append(Case(f"bpnn-json-{key}-{len(cases)}", json_mut(fn, key)))
    for vid, write in _bin_file_variants():
        for suffix in (".safetensors",):  # the .json beside it is a copy for people and tools

            def make(d: Path, files: dict[str, Path], write: Any = write, suffix: str = suffix
                     ) -> Any:  # fmt: skip
                src = files["checkpoint"]
                for s in (".safetensors", ".json"):
                    if s != suffix:
                        (d / f"ck{s}").write_bytes(src.with_suffix(s).read_bytes())
                write(d / f"ck{suffix}", src.with_suffix(suffix))
                return ["sonar", "evaluate", str(d / "ck"), str(files["dataset"])], (f"ck{suffix}",)

            cases.append(Case(f"bpnn-{suffix[1:]}-{vid}", make))
    return cases


@pytest.fixture(scope="module")
def pilotnet_files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A PilotNet checkpoint (untrained) and a small valid driving log."""
    pytest.importorskip("torch")
    from uvnav.driving.dataset import LogWriter
    from uvnav.learning import PilotNetConfig
    from uvnav.learning.checkpoint import save_checkpoint
    from uvnav.learning.pilotnet import build_pilotnet

    d = tmp_path_factory.mktemp("pilotnet")
    model = build_pilotnet(PilotNetConfig())
    ck = save_checkpoint(model, d / "model.safetensors", record={"epochs": 0})
    data = d / "data"
    w = LogWriter(data)
    rng = np.random.default_rng(0)
    for k in range(12):
        img = rng.integers(0, 255, size=(66, 200, 3), dtype=np.uint8)
        w.write(f"k{k}", (img, img, img), steering=0.1 * (k % 3 - 1), throttle=0.5, brake=0.0,
                speed=10.0)  # fmt: skip
    w.close()
    return {"checkpoint": ck, "data": data}


def _pilotnet_cases() -> list[Case]:
    cases = []

    def header_mut(fn: Callable[[dict[str, Any]], Any], what: str) -> Callable[..., Any]:
        def make(d: Path, files: dict[str, Path]) -> Any:
            from safetensors import safe_open
            from safetensors.torch import load_file, save_file

            src = files["checkpoint"]
            with safe_open(str(src), framework="pt") as fh:
                header = json.loads(fh.metadata()["uvnav"])
            fn(header)
            f = d / "m.safetensors"
            save_file(load_file(str(src)), str(f), metadata={"uvnav": json.dumps(header)})
            return ["drive", "evaluate", str(f), "--seeds", "1000", "--max-steps", "10",
                    "--no-expert"], (str(f), what)  # fmt: skip

        return make

    def cfg(key: str, value: Any) -> Callable[[dict[str, Any]], None]:
        def f(h: dict[str, Any]) -> None:
            h["config"][key] = value

        return f

    def drop(key: str) -> Callable[[dict[str, Any]], None]:
        return lambda h: h.pop(key, None)

    muts: list[tuple[str, Callable[[dict[str, Any]], Any], str]] = [
        ("no-config", drop("config"), "config"),
        ("no-format", drop("format"), "format"),
        ("config-str", lambda h: h.update(config="big"), "config"),
        ("config-extra", cfg("colour", "red"), "colour"),
    ]
    for key in ("height", "width"):
        for name, value in (("str", "66"), ("huge", 4000), ("zero", 0), ("negative", -66),
                            ("float", 66.5), ("nan", NAN), ("none", None)):  # fmt: skip
            muts.append((f"{key}-{name}", cfg(key, value), key))
    for key in ("n_outputs", "extra_inputs", "dropout", "target_speed_max"):
        for name, value in (("str", "x"), ("negative", -1), ("nan", NAN), ("huge", 1e12)):
            muts.append((f"{key}-{name}", cfg(key, value), key))
    for mid, fn, what in muts:
        cases.append(Case(f"pilotnet-header-{mid}", header_mut(fn, what)))
    for vid, write in _bin_file_variants():
        if vid == "pickle":
            continue

        def make(d: Path, files: dict[str, Path], write: Any = write) -> Any:
            f = d / "m.safetensors"
            write(f, files["checkpoint"])
            return ["drive", "evaluate", str(f), "--seeds", "1000", "--max-steps", "10",
                    "--no-expert"], (str(f),)  # fmt: skip

        cases.append(Case(f"pilotnet-file-{vid}", make))
    return cases


def _driving_log_cases() -> list[Case]:
    cases = []

    def log_mut(fn: Callable[[Path], Any], what: str) -> Callable[..., Any]:
        def make(d: Path, files: dict[str, Path]) -> Any:
            import shutil

            data = d / "data"
            shutil.copytree(files["data"], data)
            fn(data)
            return ["drive", "train", str(data), "--epochs", "1", "--out",
                    str(d / "m.safetensors")], (what,)  # fmt: skip

        return make

    def img(i: int, content: bytes | None) -> Callable[[Path], None]:
        def f(data: Path) -> None:
            p = sorted((data / "IMG").iterdir())[i]
            if content is None:
                p.unlink()
            else:
                p.write_bytes(content)

        return f

    def cell(row: int, col: int, value: str | None) -> Callable[[Path], None]:
        def f(data: Path) -> None:
            log = data / "driving_log.csv"
            rows = log.read_text().splitlines()
            parts = rows[row].split(",")
            if value is None:
                del parts[col]
            else:
                parts[col] = value
            rows[row] = ",".join(parts)
            log.write_text("\n".join(rows) + "\n")

        return f

    def log_bytes(content: bytes | None) -> Callable[[Path], None]:
        def f(data: Path) -> None:
            log = data / "driving_log.csv"
            if content is None:
                log.unlink()
                log.mkdir()
            else:
                log.write_bytes(content)

        return f

    muts: list[tuple[str, Callable[[Path], Any], str]] = [
        ("img-garbage", img(0, bytes(range(256)) * 4), "IMG"),
        ("img-empty", img(1, b""), "IMG"),
        ("img-text", img(2, b"not an image"), "IMG"),
        ("img-missing", img(3, None), "IMG"),
        ("log-empty", log_bytes(b""), "driving_log.csv"),
        ("log-binary", log_bytes(bytes(range(256)) * 4), "driving_log.csv"),
        ("log-directory", log_bytes(None), "driving_log.csv"),
    ]
    for col in (3, 4, 5, 6):
        for name, value in (("nan", "nan"), ("inf", "inf"), ("str", "fast"), ("empty", "")):
            muts.append((f"row2-col{col}-{name}", cell(2, col, value), "driving_log.csv"))
    muts.append(("row2-short", cell(2, 6, None), "driving_log.csv"))
    muts.append(("row2-path-missing", cell(2, 0, "IMG/nope.jpg"), "nope.jpg"))
    for mid, fn, what in muts:
        cases.append(Case(f"drivelog-{mid}", log_mut(fn, what)))

    def opt(o: str, v: str) -> Callable[..., Any]:
        def make(d: Path, files: dict[str, Path]) -> Any:
            return ["drive", "train", str(files["data"]), "--epochs", "1", "--out",
                    str(d / "m.safetensors"), o, v], (o,)  # fmt: skip

        return make

    for o, v in (("--device", "tpu"), ("--device", "cuda:99"), ("--device", ""),
                 ("--lr", "nan"), ("--lr", "-1"), ("--batch-size", "0"), ("--epochs", "0"),
                 ("--bins", "0"), ("--head", "brake"), ("--threads", "9"),
                 ("--correction", "inf"), ("--target-speed-max", "0")):  # fmt: skip
        cases.append(Case(f"drive-train-opt{o}={v}", opt(o, v)))

    def eval_opt(o: str, v: str) -> Callable[..., Any]:
        def make(d: Path, files: dict[str, Path]) -> Any:
            return ["drive", "evaluate", str(files["checkpoint"]), "--seeds", "1000",
                    "--max-steps", "10", "--no-expert", o, v], (o,)  # fmt: skip

        return make

    for o, v in (("--throttle", "nitro"), ("--backend", "tensorrt"), ("--max-speed", "inf"),
                 ("--speed-factor", "nan")):  # fmt: skip
        cases.append(Case(f"drive-eval-opt{o}={v}", eval_opt(o, v)))
    return cases


# ------------------------------------------------------------------------------- the tests

_SCENE_MUST, _SCENE_TOLERATED = _scene_cases()
PLAIN_CASES: list[Case] = [
    *_SCENE_MUST,
    *_scene_semantic_cases(),
    *_pedestrian_cases(),
    *_campaign_cases(),
    *_database_cases(),
    *_dem_cases(),
    *_recon_option_cases(),
    *_option_cases(),
]
SONAR_CASES = [*_sonar_dataset_cases(), *_bpnn_checkpoint_cases()]
TORCH_CASES = [*_pilotnet_cases(), *_driving_log_cases()]

#: cases still failing: id -> reason (strict xfail, so a fix turns the corpus red until removed)
KNOWN_FAILING: dict[str, str] = {}


def _params(cases: list[Case], *marks: Any) -> list[Any]:
    out = []
    for c in cases:
        m = list(marks) + list(c.marks)
        if c.id in KNOWN_FAILING:
            m.append(pytest.mark.xfail(strict=True, reason=KNOWN_FAILING[c.id]))
        out.append(pytest.param(c, id=c.id, marks=m))
    return out


def test_corpus_is_large_enough() -> None:
    n = len(PLAIN_CASES) + len(SONAR_CASES) + len(TORCH_CASES)
    assert n >= 250, n
    assert len({c.id for c in [*PLAIN_CASES, *SONAR_CASES, *TORCH_CASES]}) == n  # unique ids


@pytest.mark.parametrize("case", _params(PLAIN_CASES))
def test_malformed_input(case: Case, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    argv, words = case.make(tmp_path)
    _check(runner.invoke(app, argv), words)


@pytest.mark.parametrize("case", _params(SONAR_CASES))
def test_malformed_sonar_input(
    case: Case, sonar_files: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    argv, words = case.make(tmp_path, sonar_files)
    _check(runner.invoke(app, argv), words)


@pytest.mark.slow
@pytest.mark.parametrize("case", _params(TORCH_CASES))
def test_malformed_torch_input(
    case: Case, pilotnet_files: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    argv, words = case.make(tmp_path, pilotnet_files)
    _check(runner.invoke(app, argv), words)


@pytest.mark.parametrize("case", [pytest.param(c, id=c.id) for c in _SCENE_TOLERATED])
def test_tolerated_variants_never_trace_back(case: Case, tmp_path: Path) -> None:
    argv, _ = case.make(tmp_path)
    r = runner.invoke(app, argv)
    assert "Traceback" not in r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    if r.exit_code != 0:
        lines = [ln for ln in r.output.splitlines() if ln.strip()]
        assert r.exit_code == 2 and len(lines) == 1 and lines[0].startswith("error:"), r.output


def test_valid_inputs_of_the_corpus_are_valid(tmp_path: Path) -> None:
    """The corpus's starting points load: the failures above come from the mutations."""
    for data in _scene_data().values():
        f = tmp_path / "scene.yaml"
        f.write_text(_dump(data))
        r = runner.invoke(app, ["scenarios", "validate", str(f)])
        assert r.exit_code == 0, r.output
    (tmp_path / "peds.txt").write_text(PEDS)
    r = runner.invoke(app, ["scenarios", "validate", str(_crowd_scene(tmp_path))])
    assert r.exit_code == 0, r.output
    assert math.isfinite(float(PEDS.split()[2]))
