"""Help that reads well at 80 columns, and the shared options meaning the same everywhere.

Every command's ``--help`` is rendered at ``COLUMNS=80``: lines fit, units such as ``[m]`` are
printed as written (not eaten as rich markup), no internal design references, command summaries
wrapped rather than cut, no line broken inside a hyphenated name.  ``--seed``, ``--json``,
``--plot``, ``--controller``/``-c`` and ``--param``/``-p`` have the same flags, type and wording
on every command that has them.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import typer
from typer.testing import CliRunner

from uvnav.cli.app import app

runner = CliRunner()
ENV = {"COLUMNS": "80", "TERM": "dumb"}


def _tree(cmd: Any, path: tuple[str, ...]) -> Iterator[tuple[tuple[str, ...], Any]]:
    yield path, cmd
    for name, sub in sorted(getattr(cmd, "commands", {}).items()):
        yield from _tree(sub, (*path, name))


COMMANDS = list(_tree(typer.main.get_command(app), ()))


def _options(cmd: Any) -> list[Any]:
    return [p for p in cmd.params if p.param_type_name == "option"]


def _type(param: Any) -> Any:
    descriptor = getattr(param, "type_descriptor", None)  # Typer with its own click
    if descriptor is not None:
        return descriptor.annotation
    return {"INT": int, "BOOL": bool, "TEXT": str, "PATH": Path}.get(
        getattr(param.type, "name", "").upper(), param.type
    )


def _help(path: tuple[str, ...]) -> str:
    result = runner.invoke(app, [*path, "--help"], env=ENV)
    assert result.exit_code == 0, (path, result.output)
    return result.stdout


@pytest.mark.parametrize("path", [p for p, _ in COMMANDS], ids=lambda p: " ".join(p) or "uvnav")
def test_help_fits_80_columns_and_reads_as_written(path: tuple[str, ...]) -> None:
    text = _help(path)
    for line in text.splitlines():
        assert len(line) <= 80, (path, line)
        assert not re.search(r"\w-$", line), (path, "broken inside a hyphenated word", line)
    assert "DESIGN" not in text and "§" not in text
    assert "``" not in text  # reST literals are for the API docs
    assert "..." not in text.split("Commands:")[-1] if "Commands:" in text else True
    assert "Usage: uvnav" in text


def test_units_in_help_survive() -> None:
    recon = _help(("recon", "plan"))
    assert "Footprint radius R [m] of the lattice" in recon
    assert "Camera cone full angle [deg]" in recon
    assert "PI target speed [m/s]" in _help(("drive", "evaluate"))
    assert "Sonar range noise std [m]" in _help(("sonar", "dataset"))


def test_command_summaries_are_wrapped_not_cut() -> None:
    root = _help(())
    assert "UAV reconnaissance over terrain (thesis Ch. 7): lattice" in root
    assert "waypoints, smooth tours." in root


SHARED: dict[str, dict[str, Any]] = {
    "--seed": {"opts": ["--seed"], "type": int, "flag": False, "multiple": False},
    "--json": {"opts": ["--json"], "type": bool, "flag": True, "multiple": False},
    "--plot": {"opts": ["--plot"], "type": Path, "flag": False, "multiple": False},
    "--controller": {"opts": ["--controller", "-c"], "type": str, "flag": False, "multiple": False},
    "--param": {"opts": ["--param", "-p"], "type": str, "flag": False, "multiple": True},
}
HELP = {
    "--seed": r"^(Episode seed|Seed of) ",
    "--json": r"^Print one JSON (object|array)\b.* instead of the table\.$",
    "--plot": r"^Also draw .* into this image file\.$",
    "--controller": r"^Law name\b",
    "--param": r"^Law parameter KEY=VALUE \(repeatable; value read as YAML\)\.$",
}


def test_shared_options_mean_the_same_on_every_command() -> None:
    seen: dict[str, int] = dict.fromkeys(SHARED, 0)
    for path, cmd in COMMANDS:
        for opt in _options(cmd):
            names = [*opt.opts, *opt.secondary_opts]
            where = f"uvnav {' '.join(path)} {names}"
            # the short flags -c and -p are reserved for --controller and --param
            for short, long in (("-c", "--controller"), ("-p", "--param")):
                assert short not in names or long in names, where
            key = next((n for n in names if n in SHARED), None)
            if key is None:
                continue
            seen[key] += 1
            spec = SHARED[key]
            assert sorted(opt.opts) == sorted(spec["opts"]), where
            assert opt.secondary_opts == [], where
            ann = _type(opt)
            if spec["multiple"]:
                assert opt.multiple and ann in (list[str], str), where
            else:
                assert ann is spec["type"] and not opt.multiple, where
            assert bool(opt.is_flag) == spec["flag"], where
            if key == "--seed":
                assert opt.min == 0, f"{where}: a seed is >= 0"
            assert re.search(HELP[key], opt.help or ""), (where, opt.help)
    assert all(seen.values()), seen  # the test saw each option at least once


@pytest.mark.parametrize(
    "path", [p for p, c in COMMANDS if any("--seed" in o.opts for o in _options(c))]
)
def test_every_seed_refuses_a_negative_or_non_integer_value(path: tuple[str, ...]) -> None:
    for bad in ("-1", "abc"):
        result = runner.invoke(app, [*path, "--seed", bad], env=ENV)
        assert result.exit_code == 2, (path, bad, result.output)
        assert result.stderr.startswith("error: ") and "--seed" in result.stderr
        assert len(result.stderr.splitlines()) == 1
