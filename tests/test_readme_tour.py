"""The README's whole tour on a fresh checkout: every command line of its bash blocks, in order,
at the quick size (``make tour``; CI runs it after ``make test``, whose 10-minute budget it would
not fit: ``uvnav run`` alone takes minutes).

The tracked files are copied into a fresh folder, the README's named YAML blocks (a block whose
first line is ``# NAME.yaml``) are written there, and each line runs there through the installed
console script, as a user types it, after the rewrites of :data:`QUICK` (the quick size: no
``--full``, fewer seeds, cases and epochs; ``uvnav ros2 run`` is stopped by SIGTERM after 5 s,
and ``uvnav view``, which waits for a Foxglove client, is watched by one,
:mod:`foxglove_client`, until its one episode ends).  A line announced as refused
(``# refused``) must end as one ``error:`` line with exit status 2; any other must exit 0
with no traceback.  Every line is either run or listed in
:data:`SKIP` with the reason, so a new README line that the tour does not know fails it.

Run it with ``pytest tests/test_readme_tour.py --tour`` (skipped without ``--tour``).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"

_CLUSTER = "a multi-node cluster (tests/bench/test_bench_ray_cluster.py starts one)"
#: lines not run, with why (matched at the start of the line)
SKIP: dict[str, str] = {
    "make run": "the set-up and `uvnav run`, which the tour runs itself",
    "make test": "the set-up and the test suite, which CI runs before the tour",
    "source .venv/bin/activate": "the tour runs the installed console script directly",
    "uvnav replay my_bag/": "a user's own bag; the line before it replays the tour's run.mcap",
    "ray get-auth-token": _CLUSTER,
    "ray start": _CLUSTER,
    "RAY_AUTH_MODE=token": _CLUSTER,
    "uvnav bench my-campaign.yaml --engine ray --address": "needs the cluster of the lines above",
}

#: the quick size: (pattern, replacement) applied in order to each line
QUICK: list[tuple[str, str]] = [
    (r" \[--full\]", ""),
    (r" --full\b", ""),
    (r"--seeds (\d+)-(\d+)", r"--seeds \1-\1"),  # drive evaluate: one seed
    (r"(reproduce \w+) --seeds \d+", r"\1 --seeds 1"),
    (r"--cases \d+", "--cases 20"),
    (r"--episodes \d+", "--episodes 2"),
    (r"--epochs \d+", "--epochs 1"),
    (r"--rounds \d+", "--rounds 1"),
    (r"--steps \d+", "--steps 512"),  # uvnav crowd train: a few PPO updates
    (r"^(uvnav view .*)--speed \S+", r"\1--speed 50 --once --port 0"),
    (r"^(uvnav ros2 run .*)$", r"timeout --preserve-status -k 10 -s TERM 5 \1"),
    (r"^\.venv/bin/python ", "{python} "),
    (r"^python ", "{python} "),
]

#: exit statuses of a line that the tour stops with SIGTERM (a clean stop: 0; else 143)
_STOPPED = {0, 143}
#: the most one line may take [s] (``uvnav run`` at the quick size takes several minutes)
_TIMEOUT = 1800


def readme_lines(text: str) -> list[tuple[str, bool]]:
    """Every command line of ``text``'s bash blocks (continuations joined, trailing comments
    dropped, comment-only lines skipped), with whether its comment announces a refusal.

    >>> readme_lines("```bash\\n# a note\\nuvnav simulate a:1 \\\\\\n  -c b   # refused: x\\n```")
    [('uvnav simulate a:1 -c b', True)]
    """
    out = []
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        for raw in block.replace("\\\n", " ").splitlines():
            line = raw.strip()
            if not line or line.startswith("#"):
                continue
            cmd, _, comment = [*re.split(r"(\s+#\s)", line + " ", maxsplit=1), "", ""][:3]
            out.append((" ".join(cmd.split()), comment.strip().lower().startswith("refused")))
    return out


def named_yaml_blocks(text: str) -> dict[str, str]:
    """The YAML blocks whose first line names their file (``# NAME.yaml ...``), by name.

    >>> named_yaml_blocks("```yaml\\n# c.yaml: run it\\nname: c\\n```\\n```yaml\\nx: 1\\n```")
    {'c.yaml': '# c.yaml: run it\\nname: c\\n'}
    """
    out = {}
    for block in re.findall(r"```yaml\n(.*?)```", text, flags=re.S):
        m = re.match(r"#\s*([\w.-]+\.yaml)\b", block)
        if m:
            out[m.group(1)] = block
    return out


def quick(cmd: str) -> str:
    """``cmd`` at the tour's quick size (:data:`QUICK`).

    >>> quick("uvnav reproduce ch4 --full --workers 2")
    'uvnav reproduce ch4 --workers 2'
    >>> quick("uvnav drive evaluate m.safetensors --seeds 1000-1019")
    'uvnav drive evaluate m.safetensors --seeds 1000-1000'
    """
    for pattern, repl in QUICK:
        cmd = re.sub(pattern, repl, cmd)
    return cmd.replace("{python}", sys.executable)


def checkout(dest: Path) -> Path:
    """The tracked files of this repository copied into ``dest`` (a fresh checkout with no build
    output, no results and no venv)."""
    files = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True
    ).stdout.split(b"\0")
    for name in filter(None, files):
        src = ROOT / os.fsdecode(name)
        if src.is_file():
            (dest / os.fsdecode(name)).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / os.fsdecode(name))
    return dest


@pytest.mark.slow
def test_the_readme_tour_runs_on_a_fresh_checkout(
    request: pytest.FixtureRequest, tmp_path: Path
) -> None:
    if not request.config.getoption("--tour"):
        pytest.skip("the README tour runs with --tour (make tour)")
    if not (ROOT / ".git").exists():
        pytest.skip("the tour copies the tracked files of a git checkout")
    text = README.read_text(encoding="utf-8")
    lines = readme_lines(text)
    assert len(lines) >= 60, "the README's tour"
    work = checkout(tmp_path / "checkout")
    for name, body in named_yaml_blocks(text).items():
        (work / name).write_text(body, encoding="utf-8")
    bindir = Path(sys.executable).parent
    env = {
        **os.environ,
        "PATH": f"{bindir}{os.pathsep}{os.environ['PATH']}",
        "SDL_VIDEODRIVER": "dummy",
        "CYCLONEDDS_URI": _LOOPBACK,
        "COLUMNS": "80",
    }
    failed, ran = [], []
    for line, refused in lines:
        if any(line.startswith(s) for s in SKIP):
            continue
        cmd = quick(line)
        tic = time.perf_counter()
        run = _watched(cmd, work, env) if cmd.startswith("uvnav view ") else _run(cmd, work, env)
        ran.append(f"{time.perf_counter() - tic:7.1f} s  {cmd}")
        said = run.stdout + run.stderr
        if refused:
            ok = run.returncode == 2 and re.fullmatch(r"error: [^\n]*\n", run.stderr) is not None
        elif cmd.startswith("timeout "):
            ok = run.returncode in _STOPPED
        else:
            ok = run.returncode == 0
        if not ok or "Traceback" in said or "internal error" in said:
            failed.append(f"{cmd}: exit {run.returncode}: {said.strip().splitlines()[-3:]}")
    print("\n".join(ran))
    assert not failed, "\n".join(failed)


def _run(cmd: str, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        cmd, shell=True, cwd=cwd, env=env, capture_output=True, text=True, timeout=_TIMEOUT
    )


def _watched(cmd: str, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """Run a ``uvnav view ... --once`` line with a Foxglove client subscribed to its topics (the
    episode starts when one is), until it exits."""
    from foxglove_client import session, view_port

    proc = subprocess.Popen(
        cmd, shell=True, cwd=cwd, env={**env, "PYTHONUNBUFFERED": "1"}, text=True,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    try:
        _, _, got = session(view_port(proc))
        out, err = proc.communicate(timeout=_TIMEOUT)
    finally:
        proc.kill()
    if not got:
        err += "no message reached the Foxglove client\n"
    return subprocess.CompletedProcess(cmd, proc.returncode, out, err)


#: Cyclone DDS on the loopback interface only (``uvnav ros2 run`` finds no robot on the network)
_LOOPBACK = (
    '<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any"><General>'
    '<Interfaces><NetworkInterface name="lo"/></Interfaces>'
    "<AllowMulticast>false</AllowMulticast></General></Domain></CycloneDDS>"
)
