"""Chapter 5's closed-loop campaigns: episodes in the results store, resume after an interruption,
the jobs of each campaign, the section."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from uvnav.bench.store import ResultsStore
from uvnav.experiments import ch5 as r5
from uvnav.experiments.ch5 import (
    LAW,
    ch5_job,
    run_jobs,
    stored_rows,
    summarise,
)
from uvnav.scenarios.ch5 import RANDOM_CH5_VERSION

#: a short scene (8 m, one small deforming star across the line): ~1 s per episode
SHORT_SCENE = """
name: short-ch5
dim: 3
t_max: 30
robot: {start: [0, 0, 0], heading: [1, 0, 0], goal: [9, 0, 0], v_max: 1.0, u_max: 1.0, radius: 0.5}
sonar: {ring_angle_deg: 35, half_angle_deg: 20, max_range: 8.0}
obstacles:
  - {type: star, centre: [4.5, 0.3, 0.0], base_radius: 1.0, shape_scale: 0.2, delta_max: 0.1,
     max_frequency: 0.5, seed: 3}
controller: {name: zhang2022-uuv3d-v1, locator: geometric}
"""


@pytest.fixture
def short_scene(tmp_path: Path) -> str:
    p = tmp_path / "short.yaml"
    p.write_text(SHORT_SCENE)
    return str(p)


class _KilledError(Exception):
    pass


def test_campaign_rows_are_stored_and_an_interrupted_campaign_resumes(
    tmp_path: Path, short_scene: str
) -> None:
    jobs = [ch5_job(short_scene, "geometric", 0), ch5_job(short_scene, "oracle", 0, 0.05)]
    db = tmp_path / "uvnav.sqlite"

    def stop_after_first(_done: int, _total: int) -> None:
        raise _KilledError  # the run is "killed" right after the first episode was stored

    with ResultsStore(db) as store, pytest.raises(_KilledError):
        run_jobs(jobs, store, r5.RANDOM_CAMPAIGN, progress=stop_after_first)
    with ResultsStore(db) as store:
        first = stored_rows(store, r5.RANDOM_CAMPAIGN)
        assert [(r["locator"], r["noise_std"]) for r in first] == [("geometric", 0.0)]
        first_id = store.find_episode(
            r5.RANDOM_CAMPAIGN,
            scenario=short_scene,
            controller=LAW,
            seed=0,
            params=jobs[0].store_params,
        )
        rows = run_jobs(jobs, store, r5.RANDOM_CAMPAIGN)
        assert store.count(r5.RANDOM_CAMPAIGN) == 2  # only the missing episode ran
        again = store.find_episode(
            r5.RANDOM_CAMPAIGN,
            scenario=short_scene,
            controller=LAW,
            seed=0,
            params=jobs[0].store_params,
        )
        assert again == first_id
        frame = store.episodes_frame(r5.RANDOM_CAMPAIGN)
    assert [r["locator"] for r in rows] == ["geometric", "oracle"]
    assert all(r["status"] == "success" and r["min_clearance"] > 0 for r in rows)
    assert set(frame["controller"]) == {LAW}
    extra = [json.loads(e) for e in frame["effective_params"]]
    assert all(e["n_obstacles"] == 1 and e["entered_inner_space"] is False for e in extra)
    params = [json.loads(p) for p in frame["params"]]
    assert {p["locator"] for p in params} == {"geometric", "oracle"}
    assert {p["noise_std"] for p in params} == {0.0, 0.05}
    groups = summarise(rows)
    assert {(g["locator"], g["success_rate"]) for g in groups} == {
        ("geometric", 1.0),
        ("oracle", 1.0),
    }


def test_network_jobs_key_on_the_checkpoint_digest() -> None:
    a = ch5_job("random-ch5:1", "network", 1, 0.0, "m", "aaaa")
    b = ch5_job("random-ch5:1", "network", 1, 0.0, "m", "bbbb")
    g1 = ch5_job("random-ch5:1", "geometric", 1, 0.0, None, "")
    g2 = ch5_job("random-ch5:1", "geometric", 1, 0.0, "m", "cccc")
    assert a.key != b.key  # another network: the episode runs again
    assert g1.key == g2.key  # the digest means nothing to the other locators
    # random scenes carry the generator's version: a store of older scenes is not reused
    assert g1.store_params["generator"] == RANDOM_CH5_VERSION
    assert "generator" not in ch5_job("thesis-ch5-scene1", "geometric", 0).store_params


def test_the_stages_resume_under_the_same_code_and_are_remade_under_another(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("torch")
    from uvnav.bench.stages import StageCache, StaleStageError

    def run(fingerprint: str, **kw: Any) -> tuple[StageCache, Any]:
        monkeypatch.setattr(r5, "fingerprint", lambda: fingerprint)
        cache = StageCache(tmp_path, fingerprint, **kw)
        summary = r5.reproduce_ch5(
            tmp_path, sizes=(), n_seeds=0, literal_seeds=0, n_random=0, n_test=30, scenes=[],
            closed_loop_samples=60, progress=False, cache=cache,
        )  # fmt: skip
        return cache, summary

    stages = ["ch5-data-n30-r999999", "ch5-data-n60-r10100", "ch5-row-n60-s100-residual"]
    first, s1 = run("a" * 16)
    assert first.built == stages and first.reused == []
    again, s2 = run("a" * 16)  # the same code: every stage resumed, nothing trained
    assert again.built == [] and again.reused == stages
    assert s2.learning == s1.learning
    with ResultsStore(tmp_path / "uvnav.sqlite") as store:  # its campaigns (no episode) go:
        for name in r5.CAMPAIGNS:  # only the stages are other code's
            store.delete_campaign(name)
    with pytest.raises(StaleStageError) as err:  # other code: refused before anything is made
        run("b" * 16)
    assert "\n" not in str(err.value) and "--fresh" in str(err.value)
    remade, s3 = run("b" * 16, fresh=True)  # --fresh: every stage made again by this code
    assert remade.built == stages and remade.reused == []
    drop = ("train_seconds",)
    assert [{k: v for k, v in r.items() if k not in drop} for r in s3.learning] == [
        {k: v for k, v in r.items() if k not in drop} for r in s1.learning
    ]


def test_ch5_section_shows_the_animation_and_names_failures(tmp_path: Path) -> None:
    from types import SimpleNamespace

    from uvnav.experiments.sections import ch5_section

    gif = tmp_path / "ch5_anim_thesis-ch5-scene3_network.gif"
    gif.write_bytes(b"GIF89a")
    fail = {
        "scene": "random-ch5:7",
        "seed": 7,
        "locator": "network",
        "noise_std": 0.05,
        "n_obstacles": 2,
        "status": "collision",
        "min_clearance": -0.01,
    }
    summary = SimpleNamespace(table=[], figures=[gif], json_path=None, failures=[fail])
    sec = ch5_section(summary, full=True)
    assert [f.path for f in sec.figures] == [gif]
    assert "Animation of thesis-ch5-scene3 with the network locator" in sec.figures[0].caption
    assert any("random-ch5:7 (network, noise 0.05 m): collision" in n for n in sec.notes)
    assert "ch5-random" in sec.intro and "ch5-noise" in sec.intro


def test_dense_jobs_form_their_own_campaign_and_table_rows() -> None:
    jobs = r5._campaign_jobs(2, (0.0, 0.05), Path("m"), "digest", n_dense=1)
    assert len(jobs[r5.RANDOM_CAMPAIGN]) == len(jobs[r5.NOISE_CAMPAIGN]) == 2 * len(r5.LOCATORS)
    dense = jobs[r5.DENSE_CAMPAIGN]
    assert [j.label for j in dense] == ["random-ch5-dense:0"] * len(r5.LOCATORS)
    assert all(j.store_params["noise_std"] == 0.0 and "generator" in dict(j.tags) for j in dense)
    row = {"locator": "geometric", "noise_std": 0.0, "success": True, "entered_inner_space": False}
    summary = r5.Ch5Summary(db_path=Path("x"))
    summary.closed_loop = [
        {**row, "scene": "random-ch5:0", "status": "success"},
        {**row, "scene": "random-ch5-dense:0", "status": "collision", "success": False},
    ]
    table = {t["quantity"]: t for t in r5.build_ch5_table(summary)}
    assert table["Ch5 random scenes success (geometric, noise 0.0 m)"]["measured"] == "100.0% of 1"
    dense_row = table["Ch5 dense scenes (beyond the assumptions) success (geometric, noise 0.0 m)"]
    assert dense_row["measured"] == "0.0% of 1"
    assert "random-ch5-dense:0 collision" in dense_row["note"]


def test_a_store_written_by_the_chapter_s_former_job_type_is_resumed(
    tmp_path: Path, short_scene: str
) -> None:
    """A row as the former ``Ch5Job``/``store_row`` wrote it (params = locator + noise) is the
    same episode: not run again, read back as it was stored."""
    from uvnav.sim.metrics import METRIC_NAMES

    old_params = {"locator": "oracle", "noise_std": 0.05}
    with ResultsStore(tmp_path / "uvnav.sqlite") as store:
        cid = store.campaign(r5.NOISE_CAMPAIGN, {"chapter": 5})
        store.add_episode(
            cid,
            scenario=short_scene,
            controller=LAW,
            seed=0,
            status="collision",
            params=old_params,
            metrics={m: None for m in METRIC_NAMES} | {"success": False, "collision": True},
            family=short_scene,
            effective_params={**old_params, "n_obstacles": 1, "entered_inner_space": True},
        )
        calls: list[tuple[int, int]] = []
        job = ch5_job(short_scene, "oracle", 0, 0.05)
        rows = run_jobs([job], store, r5.NOISE_CAMPAIGN, progress=lambda k, n: calls.append((k, n)))
        assert calls == [] and store.count(r5.NOISE_CAMPAIGN) == 1  # the stored episode: not run
    assert rows[0]["status"] == "collision" and rows[0]["entered_inner_space"] is True
    assert (rows[0]["locator"], rows[0]["noise_std"], rows[0]["model"]) == ("oracle", 0.05, "")
