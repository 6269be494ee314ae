"""uvnav.stages: atomic writes and the JSON-normalised keys the stage cache hashes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from uvnav.stages import normalise_key, write_atomic


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


def test_keys_are_json_normalised_and_a_non_finite_key_is_refused(tmp_path: Path) -> None:
    key = {"epochs": 2, "sizes": (1, 2), "lr": np.float64(0.5), "dir": tmp_path}
    # a tuple and a list, a numpy and a Python number, a path and its text are the same key
    assert normalise_key(key) == {"dir": str(tmp_path), "epochs": 2, "lr": 0.5, "sizes": [1, 2]}
    assert normalise_key({"n": np.arange(2)}) == {"n": [0, 1]}
    with pytest.raises(ValueError, match="Out of range float"):
        normalise_key({"x": float("nan")})
    with pytest.raises(TypeError, match="object is not JSON-able"):
        normalise_key({"x": object()})
