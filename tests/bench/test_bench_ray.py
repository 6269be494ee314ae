"""The Ray engine stores the same metrics as the local engine (Ray is started once, here); a
task whose worker dies is run again split, so that only the job that kills its worker is an
error; workers whose code fingerprint is not the driver's are refused and nothing is stored.

Skipped when Ray (extra ``uvnav[bench]``) is not installed.  Ray's start-up costs several seconds,
so the whole module is one test: under ``pytest -n`` two tests could land in two workers and start
Ray twice.
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from uvnav.bench.campaign import Job, run_campaign, run_group_batch
from uvnav.bench.ray_engine import (
    CodeMismatchError,
    _run_tasks,
    check_node_code,
    start_local_ray,
    worker_fingerprint,
)
from uvnav.bench.spec import campaign_from_dict, run_campaign_spec
from uvnav.bench.store import ResultsStore
from uvnav.bench.summary import TIMING_COLUMNS
from uvnav.cli.app import app
from uvnav.sim import METRIC_NAMES

ray = pytest.importorskip("ray")

DETERMINISTIC = [m for m in METRIC_NAMES if not m.startswith("decision_us")]
SMALL = {
    "name": "small",
    "scenarios": [{"generator": "random-ch2", "seeds": [0, 3]}],
    "controllers": [{"name": "straight-v1"}, {"name": "zhang2019-v1"}],
}
CAMPAIGN = """\
name: small
scenarios: [{generator: random-ch2, seeds: [0, 3]}]
controllers: [{name: straight-v1}, {name: zhang2019-v1}]
"""


CRASH_SEED = 20
#: seconds the start-up code check waits for a node in these tests (the engine's default: 20)
PATIENT = 300.0
#: a short scene (engine tests)
TINY = str(Path(__file__).parents[1] / "scenes" / "tiny-clear.yaml")


def crash_on_seed(job: Job) -> list[Any]:
    """A probe factory that kills its worker on :data:`CRASH_SEED` (no probe elsewhere)."""
    if job.seed == CRASH_SEED:
        os._exit(3)
    return []


@pytest.fixture(scope="module")
def ray_instance() -> Iterator[object]:
    # the workers cannot import this test module: its functions travel by value
    ray.cloudpickle.register_pickle_by_value(sys.modules[__name__])
    start_local_ray(ray, 2)  # as uvnav starts it: loopback only
    yield ray
    ray.shutdown()


def test_ray_engine_matches_local_and_cli(tmp_path: Path, ray_instance: object) -> None:
    spec = campaign_from_dict(SMALL)
    cols = ["scenario", "controller", "params_hash", "seed", "status", *DETERMINISTIC]
    frames = {}
    for engine, workers in [("local", 1), ("ray", 2)]:
        with ResultsStore(tmp_path / f"{engine}.sqlite") as store:
            run = run_campaign_spec(store, spec, engine=engine, workers=workers)
            assert (run.ran, run.errors) == (6, 0)
            df = store.episodes_frame("small")
            frames[engine] = df.sort_values(["controller", "seed"]).reset_index(drop=True)[cols]
    assert frames["ray"].equals(frames["local"])
    assert ray.is_initialized()  # a caller's Ray instance is reused, not shut down

    path = tmp_path / "c.yaml"
    path.write_text(CAMPAIGN)
    runner = CliRunner()
    tables = []
    for engine in ("ray", "local"):
        db = tmp_path / f"cli-{engine}.sqlite"
        args = ["bench", str(path), "--engine", engine, "--workers", "2", "--db", str(db)]
        result = runner.invoke(app, [*args, "--json"])
        assert result.exit_code == 0, result.output
        record = json.loads(result.stdout)
        assert (record["engine"], record["ran"], record["errors"]) == (engine, 6, 0)
        rows = record["controllers"]
        for row in rows:
            for col in TIMING_COLUMNS:
                row.pop(col)
        tables.append(rows)
    assert tables[0] == tables[1]

    check_a_dying_worker_costs_one_job(tmp_path)
    check_other_code_is_refused_unstored()


def check_other_code_is_refused_unstored() -> None:
    """A driver whose code fingerprint is not the workers' (as if its uvnav were another one)
    is refused by the start-up check and by every task, and no outcome is handed on."""
    expected = worker_fingerprint()
    # a node not answering within the timeout is left to the per-task check (below); on a
    # loaded machine, just after the dying-worker check, its workers may take longer than the
    # default to start, so the start-up check is given ample time here
    check_node_code(ray, expected, timeout=PATIENT)  # the same code passes
    other = "0" * 16
    with pytest.raises(CodeMismatchError, match=f"code fingerprint {expected}, here {other}"):
        check_node_code(ray, other, timeout=PATIENT)
    handled: list[object] = []
    groups = [[Job(controller="straight-v1", seed=s, generator_seed=s)] for s in range(3)]
    with pytest.raises(CodeMismatchError, match="run other uvnav code than this driver"):
        _run_tasks(ray, groups, handled.append, run_group_batch, 2, 0.25, other)
    assert handled == []


def check_a_dying_worker_costs_one_job(tmp_path: Path) -> None:
    """Instant jobs are batched 16 to a task once the first are back; the task holding the job
    that kills its worker fails (after Ray's retries), is run again one job per task, and only
    that job is stored as an error."""
    jobs = [Job(controller="straight-v1", seed=s, scenario=TINY) for s in range(40)]
    with ResultsStore(tmp_path / "crash.sqlite") as store:
        run = run_campaign(
            store, "crash", jobs, workers=2, engine="ray", probe_factory=crash_on_seed
        )
        df = store.episodes_frame("crash")
    assert (run.ran, run.errors) == (40, 1)
    bad = df[df["status"] == "error"]
    assert list(bad["seed"]) == [CRASH_SEED]
    assert "Error" in str(bad["error"].iloc[0])
