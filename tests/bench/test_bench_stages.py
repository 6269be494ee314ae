"""The stage cache (uvnav.bench.stages): reuse by inputs, atomic install, refusal of a stage made
by other code, ``fresh``, and dependants keyed by their parent's product."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from uvnav.bench.stages import (
    STAGE_FILE,
    STAGES_DIR,
    StageCache,
    StaleStageError,
    stage_fingerprint,
    stage_key,
)
from uvnav.bench.store import StaleCampaignError


def _build(calls: list[str], value: object = 1) -> object:
    def build(work: Path) -> object:
        calls.append(work.name)
        (work / "product.txt").write_text("made")
        return {"v": value}

    return build


def test_a_stage_is_built_once_and_reused_by_its_inputs(tmp_path: Path) -> None:
    calls: list[str] = []
    cache = StageCache(tmp_path, fingerprint="a" * 16)
    first = cache.run("plan", {"side": 300.0, "R": (20, 30)}, _build(calls))
    assert not first.reused and first.value == {"v": 1} and len(calls) == 1
    assert (first.folder / "product.txt").read_text() == "made"
    assert first.folder == tmp_path / STAGES_DIR / stage_key("plan", {"side": 300.0, "R": [20, 30]})
    again = StageCache(tmp_path, fingerprint="a" * 16)
    second = again.run("plan", {"R": [20, 30], "side": 300.0}, _build(calls, 2))
    assert second.reused and second.value == {"v": 1} and second.id == first.id
    assert len(calls) == 1 and again.reused == ["plan"] and again.built == []
    other = again.run("plan", {"side": 600.0, "R": [20, 30]}, _build(calls, 3))
    assert not other.reused and other.value == {"v": 3} and other.key != first.key
    assert [s["name"] for s in again.stored()] == ["plan", "plan"]


def test_an_interrupted_build_stores_nothing_and_its_work_folder_resumes(tmp_path: Path) -> None:
    cache = StageCache(tmp_path, fingerprint="a" * 16)

    def interrupted(work: Path) -> object:
        (work / "episode-0").write_text("recorded")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        cache.run("data", {"n": 2}, interrupted)
    assert cache.get("data", {"n": 2}) is None
    assert not (tmp_path / STAGES_DIR / stage_key("data", {"n": 2})).exists()

    def resumed(work: Path) -> object:
        return sorted(p.name for p in work.iterdir())

    stage = StageCache(tmp_path, fingerprint="a" * 16).run("data", {"n": 2}, resumed)
    assert stage.value == ["episode-0"]  # what the interrupted build had recorded
    left = [p.name for p in (tmp_path / STAGES_DIR).iterdir() if p.suffix != ".lock"]
    assert left == [stage.key]  # no work folder left


def test_a_stage_made_by_other_code_is_refused_in_one_line_unless_fresh(tmp_path: Path) -> None:
    calls: list[str] = []
    StageCache(tmp_path, fingerprint="a" * 16).run("train", {"epochs": 3}, _build(calls))
    newer = StageCache(tmp_path, fingerprint="b" * 16)
    with pytest.raises(StaleStageError) as err:
        newer.run("train", {"epochs": 3}, _build(calls, 2))
    msg = str(err.value)
    assert "\n" not in msg and "'train'" in msg and "--fresh" in msg and "a" * 16 in msg
    assert isinstance(err.value, StaleCampaignError) and len(calls) == 1
    assert newer.run("train", {"epochs": 4}, _build(calls, 4)).value == {"v": 4}  # other inputs
    fresh = StageCache(tmp_path, fingerprint="b" * 16, fresh=True)
    remade = fresh.run("train", {"epochs": 3}, _build(calls, 5))
    assert remade.value == {"v": 5} and not remade.reused and len(calls) == 3
    assert fresh.run("train", {"epochs": 3}, _build(calls, 6)).value == {"v": 5}  # once a run
    rec = json.loads((remade.folder / STAGE_FILE).read_text())
    assert rec["fingerprint"] == "b" * 16 and rec["inputs"] == {"epochs": 3}


def test_a_remade_parent_gives_its_dependants_new_keys(tmp_path: Path) -> None:
    calls: list[str] = []
    cache = StageCache(tmp_path, fingerprint="a" * 16)
    parent = cache.run("train", {"epochs": 1}, _build(calls))
    child = cache.run("loop", {"model": parent.ref}, _build(calls))
    again = StageCache(tmp_path, fingerprint="a" * 16, fresh=True)
    parent2 = again.run("train", {"epochs": 1}, _build(calls))
    assert parent2.key == parent.key and parent2.id != parent.id
    plain = StageCache(tmp_path, fingerprint="a" * 16)
    child2 = plain.run("loop", {"model": parent2.ref}, _build(calls))
    assert child2.key != child.key and not child2.reused


def test_the_fingerprint_follows_the_code_and_the_version(monkeypatch: pytest.MonkeyPatch) -> None:
    import uvnav

    a = stage_fingerprint("recon")
    assert a == stage_fingerprint("recon") and len(a) == 16
    assert a != stage_fingerprint("recon", "geometry")
    monkeypatch.setattr(uvnav, "__version__", "0.0.0+other")
    assert stage_fingerprint("recon") != a


def test_a_stage_another_process_is_building_is_refused_at_once(tmp_path: Path) -> None:
    import fcntl
    import os

    from uvnav.bench.store import StoreInUseError

    key = stage_key("train", {"epochs": 3})
    (tmp_path / STAGES_DIR).mkdir()
    fd = os.open(tmp_path / STAGES_DIR / f".{key}.lock", os.O_RDWR | os.O_CREAT)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # as another process building it
        os.write(fd, b"4242\n")
        calls: list[str] = []
        cache = StageCache(tmp_path, fingerprint="a" * 16)
        with pytest.raises(
            StoreInUseError, match=r"stage 'train' .* another uvnav process \(pid 4242\)"
        ):
            cache.run("train", {"epochs": 3}, _build(calls))
        assert calls == []
    finally:
        os.close(fd)
    assert cache.run("train", {"epochs": 3}, _build(calls)).value == {"v": 1}
