"""``uvnav simulate --mcap``: the episode file opened before the run and closed after it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from uvnav.cli.errors import CliError

#: the scene kinds whose episodes are written as MCAP
KINDS = ("nav2d", "multi2d")


def open_episode(path: Path, resolved: Any, law: str | None, seed: int | None) -> Any:
    """A :class:`uvnav.bags.mcap.McapEpisode` writing into ``path`` for a run of ``resolved``
    with ``law`` (default: the scene's) and ``seed`` (its metadata: scene, law, seed).

    Raises:
        CliError: another scene kind; a folder or a path in a missing folder; a file that
            cannot be written (status 2); the ``ros`` extra missing (status 1).
    """
    kind = resolved.kind.name
    if kind not in KINDS:
        raise CliError(
            f"--mcap: episodes of {kind} scenes are not written yet ({' and '.join(KINDS)} are)"
        )
    if path.is_dir():
        raise CliError(f"--mcap {path}: is a directory; give a file such as run.mcap")
    if not path.parent.is_dir():
        raise CliError(f"--mcap {path}: no such directory {path.parent}")
    from uvnav.bags import MissingExtraError
    from uvnav.bags.mcap import McapEpisode
    from uvnav.scenarios.episodes import default_law, episode_seed

    name = law or default_law(resolved)[0]
    meta = {"scene": str(resolved.name), "law": name, "seed": str(episode_seed(resolved, seed))}
    try:
        return McapEpisode.open(path, meta)
    except MissingExtraError as exc:
        raise CliError(str(exc), code=1) from None
    except OSError as exc:
        raise CliError(f"--mcap {path}: cannot write: {exc.strerror or exc}") from None


def close_episode(episode: Any, ok: bool) -> None:
    """End ``episode``'s file; without ``ok`` (the run failed) remove it."""
    episode.close()
    if not ok:
        Path(episode.path).unlink(missing_ok=True)
