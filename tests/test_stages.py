"""The one stage cache (uvnav.stages): atomic writes, reuse and invalidation of stages."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from uvnav.stages import Stages, normalise_key, write_atomic


def test_write_atomic_writes_bytes_text_and_callables(tmp_path: Path) -> None:
    write_atomic(tmp_path / "a" / "b.bin", b"\x00\x01")
    write_atomic(tmp_path / "t.txt", "héllo")
    write_atomic(tmp_path / "f.npz", lambda fh: np.savez(fh, x=np.arange(3)))
    assert (tmp_path / "a" / "b.bin").read_bytes() == b"\x00\x01"
    assert (tmp_path / "t.txt").read_text(encoding="utf-8") == "héllo"
    with np.load(tmp_path / "f.npz") as z:
        assert z["x"].tolist() == [0, 1, 2]
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a", "b.bin", "f.npz", "t.txt"]


def test_a_writer_that_raises_midway_leaves_no_partial_file(tmp_path: Path) -> None:
    def half(fh) -> None:  # type: ignore[no-untyped-def]
        fh.write(b"first half")
        raise RuntimeError("interrupted")

    target = tmp_path / "data.npz"
    with pytest.raises(RuntimeError, match="interrupted"):
        write_atomic(target, half)
    assert list(tmp_path.iterdir()) == []  # neither the file nor a temporary one
    # over an existing file: the previous content stays whole
    write_atomic(target, b"previous")
    with pytest.raises(RuntimeError):
        write_atomic(target, half)
    assert target.read_bytes() == b"previous" and list(tmp_path.iterdir()) == [target]


def test_an_interrupted_stage_put_keeps_the_previous_record(tmp_path: Path) -> None:
    st = Stages(tmp_path)
    st.put("a", {"n": 1}, {"v": 1})
    with pytest.raises(TypeError):
        st.put("a", {"n": 1}, {"v": object()})  # not JSON-able: fails before anything is written
    assert Stages(tmp_path).get("a", {"n": 1}) == {"v": 1}


def test_a_stage_is_reused_with_the_same_key_and_its_files(tmp_path: Path) -> None:
    st = Stages(tmp_path)
    model = tmp_path / "model.bin"
    assert st.get("train", {"epochs": 2}, (model,)) is None
    model.write_bytes(b"w")
    st.put("train", {"epochs": 2, "sizes": (1, 2), "lr": np.float64(0.5)}, {"loss": [0.1]})
    again = Stages(tmp_path)
    # keys are JSON-normalised: a tuple and a list, a numpy and a Python number are the same
    assert again.get("train", {"lr": 0.5, "sizes": [1, 2], "epochs": 2}, (model,)) == {
        "loss": [0.1]
    }
    assert again.reused == ["train"]
    assert again.get("train", {"epochs": 3, "sizes": [1, 2], "lr": 0.5}) is None  # other key
    model.unlink()
    assert again.get("train", {"epochs": 2, "sizes": [1, 2], "lr": 0.5}, (model,)) is None
    (tmp_path / "broken.json").write_text("{not json")
    assert again.get("broken", {}) is None
    with pytest.raises(ValueError, match="Out of range float"):
        normalise_key({"x": float("nan")})
    with pytest.raises(ValueError, match="stage name"):
        again.path("../escape")


def test_a_recomputed_stage_invalidates_the_stages_built_on_it(tmp_path: Path) -> None:
    def run(epochs: int) -> Stages:
        st = Stages(tmp_path)
        if st.get("train", {"epochs": epochs}) is None:
            st.put("train", {"epochs": epochs}, "model")
        if st.get("readout", {"model": st.ref("train")}) is None:
            st.put("readout", {"model": st.ref("train")}, "readout")
        if st.get("eval", {"model": st.ref("readout")}) is None:
            st.put("eval", {"model": st.ref("readout")}, "score")
        if st.get("expert", {"seeds": [1]}) is None:  # built on nothing
            st.put("expert", {"seeds": [1]}, "expert")
        return st

    assert run(1).reused == []
    assert run(1).reused == ["train", "readout", "eval", "expert"]
    assert run(2).reused == ["expert"]  # train recomputed: readout and eval with it
    assert run(2).reused == ["train", "readout", "eval", "expert"]
    # recomputing a middle stage (its file lost) invalidates what is built on it only
    (tmp_path / "readout.json").unlink()
    assert run(2).reused == ["train", "expert"]
    with pytest.raises(KeyError, match="neither reused nor computed"):
        Stages(tmp_path).ref("train")


def test_fresh_forgets_every_stage_and_old_stage_files_are_reused(tmp_path: Path) -> None:
    # the layout written by the older Chapter 6 code: no "format", key as given
    (tmp_path / "expert.json").write_text(
        json.dumps({"key": {"seeds": [1000], "max_steps": 30}, "id": "abc", "value": {"r": 1}})
    )
    st = Stages(tmp_path)
    assert st.get("expert", {"max_steps": 30, "seeds": [1000]}) == {"r": 1}
    assert st.ref("expert") == {"stage": "expert", "id": "abc"}
    (tmp_path / "other.json").write_text(json.dumps({"format": "x-v9", "key": {}, "value": 1}))
    assert st.get("other", {}) is None  # another format: recomputed
    assert Stages(tmp_path, fresh=True).get("expert", {"max_steps": 30, "seeds": [1000]}) is None
    assert list(tmp_path.iterdir()) == []
