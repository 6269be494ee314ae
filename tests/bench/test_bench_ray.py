"""The Ray engine stores the same metrics as the local engine (Ray is started once, here).

Skipped when Ray (extra ``uvnav[bench]``) is not installed.  Ray's start-up costs several seconds,
so the whole module is one test: under ``pytest -n`` two tests could land in two workers and start
Ray twice.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest
from typer.testing import CliRunner

from uvnav.bench.ray_engine import start_local_ray
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


@pytest.fixture(scope="module")
def ray_instance() -> Iterator[object]:
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
