"""The README's commands run as written: every ``uvnav simulate``, ``uvnav scenarios`` and
``uvnav controllers`` line of its bash blocks (and ``uvnav reproduce --list``), in order, in one
folder (a line may use the file an earlier line wrote), through the installed console script.
The long jobs (``uvnav run``, ``reproduce``, ``bench``, ``drive``, ``sonar``, the ROS tools) have
tests of their own at small sizes; a line that needs a trained network is left out."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
#: the commands this test runs: cheap, self-contained lines
_CHEAP = re.compile(r"^uvnav (simulate|scenarios|controllers|reproduce --list)\b")


def readme_commands(text: str) -> list[tuple[str, bool]]:
    """The selected command lines of ``text``'s bash blocks (continuation lines joined, trailing
    comments dropped), each with whether its comment says the command is refused.

    >>> readme_commands("```bash\\nuvnav simulate a:1 \\\\\\n  -c b   # note\\nmake run\\n```")
    [('uvnav simulate a:1 -c b', False)]
    """
    out = []
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        for line in block.replace("\\\n", " ").splitlines():
            cmd, _, comment = [*re.split(r"(\s+#\s)", line.strip() + " ", maxsplit=1), "", ""][:3]
            cmd = " ".join(cmd.split())
            comment = comment.strip()
            if _CHEAP.match(cmd) and "model=" not in cmd:
                out.append((cmd, comment.lower().startswith("refused")))
    return out


@pytest.mark.slow
def test_the_readmes_commands_run_as_written(tmp_path: Path) -> None:
    commands = readme_commands(README.read_text(encoding="utf-8"))
    assert len(commands) >= 20  # the README's tour of scenes, laws and episodes
    uvnav = shutil.which("uvnav", path=str(Path(sys.executable).parent)) or "uvnav"
    env = {**os.environ, "PATH": f"{Path(uvnav).parent}{os.pathsep}{os.environ['PATH']}"}
    failed = []
    for cmd, refused in commands:
        run = subprocess.run(
            cmd, shell=True, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
        )
        said = run.stdout + run.stderr
        # a refusal the README announces is one error line with exit status 2
        ok = (
            run.returncode == 2 and run.stderr.startswith("error: ") and run.stderr.count("\n") == 1
            if refused
            else run.returncode == 0
        )
        if not ok or "Traceback" in said or "internal error" in said:
            failed.append(f"{cmd}: exit {run.returncode}: {said.strip().splitlines()[-1:]}")
    assert not failed, "\n".join(failed)
