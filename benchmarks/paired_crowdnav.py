"""Two crowd runs compared on the same cases: the paired difference of their success rates.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/paired_crowdnav.py A.json B.json``, where each
file is what ``bench_crowdnav.py --out DIR`` wrote (``DIR/crowdnav-<law>.json``) for the same
cases and crowd.  Two laws, or one law on two vehicles, run on the same seeded cases share each
case's crowd, so their outcomes are paired: a case one wins and the other loses says more than
two separate rates.  Printed: each run's success with its 95 % Wilson interval, the cases won by
one run alone, and the difference A - B with its 95 % interval for paired data (Newcombe's
method 10, :func:`uvnav.bench.summary.paired_difference_interval`).  A file that cannot be read,
or two runs on different cases, exit with status 2 and one line naming the file and the problem.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path
from typing import Any

from uvnav.bench.summary import paired_difference_interval, wilson_interval


class PairError(ValueError):
    """A results file that cannot be paired; the message names the file and the field."""


def load_run(path: Path) -> dict[str, Any]:
    """The run in ``path`` (``bench_crowdnav.py``'s JSON), checked for its cases and statuses."""
    try:
        run = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise PairError(f"{path}: cannot be read as JSON ({exc})") from None
    if not isinstance(run, dict):
        raise PairError(f"{path}: not a bench_crowdnav.py results file")
    for field in ("case_numbers", "statuses"):
        if not isinstance(run.get(field), list):
            raise PairError(f"{path}: field {field!r} missing or not a list")
    if len(run["case_numbers"]) != len(run["statuses"]):
        raise PairError(f"{path}: {len(run['case_numbers'])} case numbers for "
                        f"{len(run['statuses'])} statuses")  # fmt: skip
    return run


def _label(run: dict[str, Any]) -> str:
    limits = run.get("accel_max"), run.get("turn_accel_max")
    vehicle = f", {run['kinematics']}" if run.get("kinematics") else ""
    if None not in limits:
        vehicle += f", limits {limits[0]:g} m/s^2, {limits[1]:g} rad/s^2"
    params = run.get("params") or {}
    shown = " ".join(f"{k}={v}" for k, v in params.items())
    return f"{run.get('law', '?')}{vehicle}{' ' + shown if shown else ''}"


def compare(a: dict[str, Any], b: dict[str, Any], names: tuple[str, str]) -> dict[str, Any]:
    """The paired comparison of runs ``a`` and ``b`` (their success on the same cases)."""
    if a["case_numbers"] != b["case_numbers"]:
        raise PairError(f"{names[1]}: field 'case_numbers' differs from {names[0]}'s "
                        "(run both on the same --first, --cases, --humans and --rule)")  # fmt: skip
    pairs = Counter((x == "success", y == "success")
                    for x, y in zip(a["statuses"], b["statuses"], strict=True))  # fmt: skip
    only_a, only_b, both = pairs[True, False], pairs[False, True], pairs[True, True]
    diff, lo, hi = paired_difference_interval(only_a, only_b, both, pairs[False, False])
    return {
        "cases": pairs.total(),
        "success": [both + only_a, both + only_b],
        "only": [only_a, only_b],
        "both": both,
        "difference": diff,
        "ci95": [lo, hi],
    }


def report(a: dict[str, Any], b: dict[str, Any], c: dict[str, Any]) -> str:
    """The comparison as lines of at most 80 columns."""
    n = c["cases"]
    lines = [f"paired on {n} cases ({a.get('humans', '?')} humans, {a.get('rule', '?')})"]
    for tag, run, wins, only in zip("AB", (a, b), c["success"], c["only"], strict=True):
        lo, hi = wilson_interval(wins, n)
        lines += [
            f"  {tag}: {_label(run)}",
            f"     success {wins / n:.3f} [{lo:.3f}, {hi:.3f}], won alone {only}",
        ]
    lo, hi = c["ci95"]
    lines.append(f"  A - B: {c['difference']:+.3f}  95% [{lo:+.3f}, {hi:+.3f}] (Newcombe, paired)")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", type=Path, help="the first run's results (A)")
    ap.add_argument("b", type=Path, help="the second run's results (B)")
    args = ap.parse_args(argv)
    try:
        a, b = load_run(args.a), load_run(args.b)
        c = compare(a, b, (str(args.a), str(args.b)))
    except PairError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(report(a, b, c))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
