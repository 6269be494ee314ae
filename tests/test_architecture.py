"""DESIGN §1: the layer contract (import-linter) and what low layers must never import."""

from __future__ import annotations

import pkgutil
import re
import shutil
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

import uvnav

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = ROOT / "pyproject.toml"

#: DESIGN §1, top (may import everything below) to bottom.
DESIGN_LAYERS = [
    {"uvnav.cli"},
    {"uvnav.ros2"},  # a law as a ROS 2 node: over controllers and sensors, beside the CLI
    {"uvnav.viz", "uvnav.bags"},  # figures; episodes and recordings in ROS 2 formats (files)
    {"uvnav.experiments"},  # the registered reproductions, over bench; renderers injected
    {"uvnav.learning", "uvnav.driving", "uvnav.bench", "uvnav.envs"},
    {"uvnav.scenarios"},
    {"uvnav.sim"},
    {"uvnav.controllers", "uvnav.recon"},
    {"uvnav.planners"},  # issue 9: below the controllers (hybrid-v1 plans with them)
    {"uvnav.sensors", "uvnav.prediction"},
    {"uvnav.dynamics", "uvnav.obstacles"},
    {"uvnav.geometry"},
    {"uvnav.core", "uvnav.stages"},  # the contract every layer reads; atomic writes
]


def _lint_imports(
    config: Path, *, pythonpath: Path | None = None, cwd: Path = ROOT
) -> subprocess.CompletedProcess[str]:
    code = textwrap.dedent(
        f"""
        import sys
        from importlinter.cli import lint_imports
        sys.exit(lint_imports(config_filename={str(config)!r}, no_cache=True, no_logo=True))
        """
    )
    env = None
    if pythonpath is not None:
        import os

        env = dict(os.environ, PYTHONPATH=str(pythonpath))
    return subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True, timeout=120
    )


def _contract_layers() -> list[set[str]]:
    cfg = tomllib.loads(PYPROJECT.read_text())["tool"]["importlinter"]
    (contract,) = [c for c in cfg["contracts"] if c["type"] == "layers"]
    layers = []
    for raw in contract["layers"]:
        parts = raw.replace(":", "|").split("|")
        layers.append({p.strip().strip("()").strip() for p in parts})
    return layers


def test_import_linter_contract_is_kept() -> None:
    proc = _lint_imports(PYPROJECT)
    assert proc.returncode == 0, f"lint-imports failed:\n{proc.stdout}\n{proc.stderr}"
    assert "BROKEN" not in proc.stdout


def test_contract_layers_follow_design() -> None:
    assert _contract_layers() == DESIGN_LAYERS


def test_every_subpackage_is_covered_by_the_contract() -> None:
    """``exhaustive = false``: a package missing from the layer list would escape the check."""
    declared = set().union(*_contract_layers())
    existing = {f"uvnav.{m.name}" for m in pkgutil.iter_modules(uvnav.__path__) if m.ispkg}
    assert existing - declared == set()


def test_contract_catches_a_layer_violation(tmp_path: Path) -> None:
    """The contract has teeth: geometry importing the simulator must break it."""
    pkg = tmp_path / "uvnav"
    shutil.copytree(Path(uvnav.__file__).parent, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    (pkg / "geometry" / "_violation.py").write_text("from uvnav.sim import run_episode  # noqa\n")
    proc = _lint_imports(PYPROJECT, pythonpath=tmp_path, cwd=tmp_path)
    assert proc.returncode != 0
    assert "uvnav.geometry is not allowed to import uvnav.sim" in proc.stdout, (
        proc.stdout + proc.stderr
    )


HEAVY = ("torch", "matplotlib", "plotly", "gymnasium", "ray")
LOW_LAYERS = [
    "uvnav.geometry",
    "uvnav.dynamics",
    "uvnav.obstacles",
    "uvnav.sensors",
    "uvnav.prediction",
    "uvnav.planners",
    "uvnav.sim",
    "uvnav.stages",
]


@pytest.mark.parametrize("module", LOW_LAYERS)
def test_low_layers_do_not_import_heavy_dependencies(module: str) -> None:
    code = textwrap.dedent(
        f"""
        import importlib, sys
        importlib.import_module({module!r})
        loaded = sorted(m for m in {HEAVY!r} if m in sys.modules)
        print(",".join(loaded))
        """
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True
    )
    assert proc.stdout.strip() == "", f"importing {module} loaded {proc.stdout.strip()}"


SRC = ROOT / "src" / "uvnav"
#: a chapter's name in any spelling: what the campaign engine must not mention
CHAPTER = re.compile(r"ch[2-7]|chapter", re.IGNORECASE)


def test_bench_is_the_campaign_engine_only() -> None:
    """The experiments live in uvnav.experiments; no module of bench names a chapter."""
    named = [
        f"{p.relative_to(SRC)}:{n}"
        for p in sorted((SRC / "bench").rglob("*.py"))
        for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
        if CHAPTER.search(line)
    ]
    assert named == [], f"bench names a chapter: {', '.join(named)}"


def test_no_module_of_uvnav_exceeds_800_lines() -> None:
    long = {
        str(p.relative_to(SRC)): n
        for p in sorted(SRC.rglob("*.py"))
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > 800
    }
    assert long == {}
