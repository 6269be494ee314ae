"""SQLite results store for campaigns (DESIGN §5).

One database file holds three tables:

``campaigns``
    ``id``, ``name`` (unique), ``created`` (ISO 8601 UTC), ``config`` (JSON text).
``episodes``
    one row per finished episode: ``campaign_id``, ``scenario``, ``family`` (the scenario family a
    report groups by, e.g. ``crowdnav-circle`` for generated scenes), ``controller``,
    ``params_hash``, ``params`` (JSON of the job's controller parameters, the hashed ones),
    ``effective_params`` (JSON of what the controller was finally built with), ``seed``, ``status``
    (``success``, ``collision``, ``timeout`` or ``error``), ``error`` (message, NULL unless status
    is ``error``), every metric of :data:`uvnav.sim.METRIC_NAMES` as its own column under exactly
    that name, ``wall_time`` [s] and ``created``. ``UNIQUE(campaign_id, scenario, controller,
    params_hash, seed)`` is the resume key.
``trajectories``
    ``episode_id`` and ``data``: a compressed ``.npz`` blob of the :class:`uvnav.sim.Trajectory`
    arrays (optional, written only for recorded episodes).

Design choices, after what sweep tools such as Optuna's RDB storage and Sacred's observers do:

* WAL journal mode, so readers (``pandas.read_sql``, a report) never block the writer and a crash
  leaves a consistent file.  Only the campaign's main process writes; workers return results.
* One transaction per finished episode (episode row + trajectory blob together): a killed campaign
  loses at most the episodes in flight.
* Missing values are SQL ``NULL`` — never NaN (a NaN or ±inf metric is written as NULL), so SQL
  aggregates and pandas agree on what is missing.
* An ``error`` row may be overwritten by a later retry of the same key; a finished (non-error)
  episode never is, so a resumed campaign cannot duplicate or silently change results.
* Opening an older database adds any metric column it lacks (``ALTER TABLE ADD COLUMN``), so
  adding a metric to :data:`~uvnav.sim.METRIC_NAMES` does not break existing result files (the
  social metrics of :mod:`uvnav.sim.social` came so; their episodes read NULL there).  Opened
  read-only, such a file is not changed, and its missing columns read as missing values.
* One campaign writer per database: :meth:`ResultsStore.writer_lease` holds an exclusive
  ``flock`` on ``<db>.lock`` beside the file (with the holder's pid in it) while a campaign
  runs, so a second ``uvnav bench`` on the same database refuses at once
  (:class:`StoreInUseError`) instead of running every episode again and failing on the first
  duplicate.  The lock is the kernel's: it goes away with the process, however it ends, and the
  file left behind is harmless.
"""

from __future__ import annotations

import dataclasses
import hashlib
import io
import json
import math
import os
import sqlite3
import urllib.parse
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import AbstractContextManager, contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from uvnav.sim import METRIC_NAMES, EpisodeMetrics, EpisodeResult, Trajectory

if TYPE_CHECKING:
    import pandas as pd

#: Metrics stored as SQL INTEGER (booleans as 0/1) and as TEXT; every other metric is REAL.
_INTEGER_METRICS = frozenset({"success", "collision", "limit_violations", "mode_switches"})
_TEXT_METRICS = frozenset({"collision_by"})
_BOOLEAN_METRICS = ("success", "collision")

#: Resume key of an episode inside one campaign: (scenario, controller, params_hash, seed).
EpisodeKey = tuple[str, str, str, int]

STATUS_ERROR = "error"
#: an episode not run: its scene breaks an assumption the law declares (the reason is stored)
STATUS_REFUSED = "refused"


def _metric_sql_type(name: str) -> str:
    if name in _TEXT_METRICS:
        return "TEXT"
    return "INTEGER" if name in _INTEGER_METRICS else "REAL"


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return dataclasses.asdict(obj)
    raise TypeError(f"cannot store {type(obj).__name__} as JSON")


def canonical_json(value: Any) -> str:
    """Deterministic JSON text (sorted keys, no whitespace) used for storage and hashing."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), default=_json_default)


def params_hash(params: Mapping[str, Any] | None) -> str:
    """Stable 16-hex-digit hash of a controller parameter mapping (key order does not matter)."""
    return hashlib.sha256(canonical_json(dict(params or {})).encode()).hexdigest()[:16]


def _sql_value(value: Any) -> Any:
    """A metric value as SQLite will store it: NaN/inf and None become NULL, bools 0/1, text
    (``collision_by``) as it is."""
    if value is None:
        return None
    if isinstance(value, str):
        return value
    if isinstance(value, bool | np.bool_):
        return int(value)
    if isinstance(value, int | np.integer):
        return int(value)
    v = float(value)
    return v if math.isfinite(v) else None


# --------------------------------------------------------------------------------------------------
# trajectory blobs
# --------------------------------------------------------------------------------------------------

_TRAJ_ARRAYS = (
    "times",
    "robot",
    "commands",
    "clearance",
    "nearest_id",
    "obstacle_centres",
    "obstacle_headings",
    "obstacle_velocities",
    "obstacle_omegas",
)


def trajectory_to_bytes(traj: Trajectory) -> bytes:
    """Serialise a trajectory as a compressed ``.npz`` (no pickled objects inside)."""
    arrays: dict[str, np.ndarray] = {name: np.asarray(getattr(traj, name)) for name in _TRAJ_ARRAYS}
    arrays["modes"] = np.asarray(traj.modes, dtype=np.str_)
    arrays["n_shapes"] = np.asarray(len(traj.obstacle_shapes))
    for j, shape in enumerate(traj.obstacle_shapes):
        arrays[f"shape_{j}"] = np.asarray(shape, dtype=float)
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)  # type: ignore[arg-type]
    return buf.getvalue()


def trajectory_from_bytes(blob: bytes) -> Trajectory:
    """Inverse of :func:`trajectory_to_bytes`."""
    with np.load(io.BytesIO(blob), allow_pickle=False) as data:
        n_shapes = int(data["n_shapes"])
        return Trajectory(
            times=data["times"],
            robot=data["robot"],
            commands=data["commands"],
            modes=[str(m) for m in data["modes"]],
            clearance=data["clearance"],
            nearest_id=data["nearest_id"],
            obstacle_centres=data["obstacle_centres"],
            obstacle_headings=data["obstacle_headings"],
            obstacle_velocities=data["obstacle_velocities"],
            obstacle_omegas=data["obstacle_omegas"],
            obstacle_shapes=[data[f"shape_{j}"] for j in range(n_shapes)],
        )


# --------------------------------------------------------------------------------------------------
# one writer per database
# --------------------------------------------------------------------------------------------------


class StoreInUseError(PermissionError):
    """Another process holds the database's writer lease (one line: the file and its pid).

    A :class:`PermissionError` (the database may not be written now), so every command of the
    CLI reports it as one ``error:`` line with exit status 2, ``uvnav run`` included.
    """


#: leases held by this process: lock-file path -> nesting depth
_LEASES: dict[str, int] = {}


def lock_path(db: str | Path) -> Path:
    """The lock file of a database: ``<db>.lock`` beside it."""
    db = Path(db)
    return db.with_name(db.name + ".lock")


@contextmanager
def pid_lock(path: Path, refused: Callable[[str], str]) -> Iterator[None]:
    """An exclusive, non-blocking ``flock`` on ``path`` whose file holds this process's pid while
    held; released on exit, whatever interrupts (Ctrl-C lands between any two bytecodes), or by
    the kernel when the process dies; none where ``flock`` does not exist (Windows).  Raises
    :class:`StoreInUseError` ``(refused(holder's pid))`` at once when another process holds it."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    fd, taken = os.open(path, os.O_RDWR | os.O_CREAT, 0o644), False
    try:  # from here on, whatever interrupts closes fd
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown"
            raise StoreInUseError(refused(holder)) from None
        taken = True
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield
    finally:
        try:
            if taken:  # clear the pid
                os.ftruncate(fd, 0)
        finally:
            os.close(fd)  # closing the descriptor releases the flock


@contextmanager
def writer_lease(db: str | Path) -> Iterator[None]:
    """Hold the exclusive right to write campaigns into ``db`` (re-entrant within a process): a
    :func:`pid_lock` on :func:`lock_path`.

    Raises:
        StoreInUseError: another process holds it (at once, without waiting).
    """
    path = lock_path(db)
    key = str(path.resolve())
    if key in _LEASES:
        _LEASES[key] += 1
        try:
            yield
        finally:
            _LEASES[key] -= 1
        return

    with pid_lock(path, lambda pid: f"database {db} is in use by another uvnav process (pid "
                  f"{pid}); wait for it to finish or use another --db"):  # fmt: skip
        try:
            _LEASES[key] = 1
            yield
        finally:
            _LEASES.pop(key, None)


# --------------------------------------------------------------------------------------------------
# the store
# --------------------------------------------------------------------------------------------------


class NotAStoreError(ValueError):
    """A file that is not a uvnav results database (one line naming it and what is missing)."""


class StaleCampaignError(RuntimeError):
    """A reproduction would have to start a stored campaign over (its rows were made by other
    code, or another generator or model version): it refuses instead of deleting another run's
    rows.  The message is one line naming the campaign, the database and how to remove it."""

    def __init__(self, db: str | Path, campaigns: str | Sequence[str], why: str) -> None:
        self.db = Path(db)
        self.campaigns = [campaigns] if isinstance(campaigns, str) else list(campaigns)
        names = ", ".join(map(repr, self.campaigns))
        it = "it" if len(self.campaigns) == 1 else "them"
        super().__init__(
            f"campaign{'s' if len(self.campaigns) > 1 else ''} {names} in {db} {why}; the rows "
            f"are kept, not mixed with new ones: remove {it} with 'uvnav forget {db} "
            f"{' '.join(self.campaigns)}' or use another --results folder"
        )


#: the config key of a campaign that holds the fingerprint of the code that made its episodes
FINGERPRINT_KEY = "fingerprint"
#: the files a fingerprint reads (sources and scenario data, never caches)
_FINGERPRINT_SUFFIXES = frozenset({".py", ".yaml", ".yml", ".json"})


def extend_fingerprint(base: str, *parts: str) -> str:
    """``base`` (a code fingerprint) extended with the files under ``parts``: paths relative
    to the ``uvnav`` package, each a source file or a folder (its ``.py``, ``.yaml``, ``.yml``
    and ``.json`` files, ``__pycache__`` left out), hashed with their relative paths.

    Returns:
        16 hex digits.
    """
    import uvnav

    root = Path(uvnav.__file__).parent
    h = hashlib.sha256(base.encode())
    for part in parts:
        path = root / part
        files = [path] if path.is_file() else sorted(path.rglob("*")) if path.is_dir() else []
        for p in files:
            if p.is_file() and p.suffix in _FINGERPRINT_SUFFIXES and "__pycache__" not in p.parts:
                h.update(str(p.relative_to(root)).encode())
                h.update(p.read_bytes())
    return h.hexdigest()[:16]


def check_fingerprints(store: ResultsStore, fingerprints: Mapping[str, str]) -> None:
    """Refuse to resume a campaign made by other code: every stored campaign named in
    ``fingerprints`` (name -> the fingerprint of the code about to run it) must have been
    created with that fingerprint (its config's :data:`FINGERPRINT_KEY`; a campaign stored
    without one was made by unknown code).  Campaigns not stored yet pass; nothing is deleted.

    Raises:
        StaleCampaignError: one line naming every stored campaign whose fingerprint differs.
    """
    stale = [
        c["name"]
        for c in store.campaigns()
        if c["name"] in fingerprints and c["config"].get(FINGERPRINT_KEY) != fingerprints[c["name"]]
    ]
    if stale:
        raise StaleCampaignError(
            store.path, stale, f"{'was' if len(stale) == 1 else 'were'} stored by other code"
        )


#: tables and columns a uvnav results database has whatever its age (metrics may be missing)
_REQUIRED = {
    "campaigns": {"id", "name", "created", "config"},
    "episodes": {"id", "campaign_id", "scenario", "controller", "params_hash", "seed", "status"},
    "trajectories": {"episode_id", "data"},
}


def connect_readonly(path: str | Path) -> sqlite3.Connection:
    """An SQLite connection that cannot write ``path`` (URI ``mode=ro``; never creates it).

    A WAL database on read-only media (a mounted archive, a CD) cannot be opened so, since
    SQLite needs to create its ``-shm`` file beside it: when its folder cannot be written, it
    is opened ``immutable``, which reads the file as it is (no writer can work there either).

    Raises:
        FileNotFoundError: no such file.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(2, "No such database file", str(path))
    uri = f"file:{urllib.parse.quote(str(path.resolve()))}?mode=ro"
    conn = sqlite3.connect(uri, uri=True, timeout=30.0, isolation_level=None)
    try:
        conn.execute("SELECT 1 FROM sqlite_master LIMIT 1").fetchall()
    except sqlite3.OperationalError:
        if not os.access(path.parent, os.W_OK):  # else a real error, which check_store reports
            conn.close()
            return sqlite3.connect(f"{uri}&immutable=1", uri=True, isolation_level=None)
    except sqlite3.DatabaseError:
        pass  # not a database: check_store says so
    return conn


def check_store(conn: sqlite3.Connection, path: str | Path) -> None:
    """Refuse a database that is not a uvnav results store (read-only check).

    Raises:
        NotAStoreError: not an SQLite file, or a table or column of the schema is missing.
    """
    try:
        tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        for table, columns in _REQUIRED.items():
            if table not in tables:
                raise NotAStoreError(
                    f"{path}: not a uvnav results database (no '{table}' table; written by "
                    "uvnav bench / uvnav run)"
                )
            have = {r[1] for r in conn.execute(f"PRAGMA table_info({table})")}
            missing = sorted(columns - have)
            if missing:
                raise NotAStoreError(
                    f"{path}: not a uvnav results database (table '{table}' has no column "
                    f"'{missing[0]}')"
                )
    except sqlite3.DatabaseError as exc:
        raise NotAStoreError(f"{path}: not a uvnav results database ({exc})") from None


class ResultsStore:
    """Campaign results in one SQLite file (see the module docstring for the schema).

    Use as a context manager or call :meth:`close`.  Not shared across processes: the campaign's
    main process owns the store and workers send their results back to it.

    Args:
        path: database file; created with its parent directory if missing (writer).
        readonly: open an existing store for reading only (reports, figures): the file is opened
            with SQLite's ``mode=ro`` and never written — no schema is created or migrated, and
            a file that is not a uvnav results database is refused.  SQLite may leave its
            ``-wal``/``-shm`` companions beside a WAL database it read.

    Raises:
        FileNotFoundError: ``readonly`` and the file does not exist.
        NotAStoreError: the file is not a uvnav results database (a directory, not SQLite, a
            corrupt or another program's SQLite database); nothing is written to it.
    """

    def __init__(self, path: str | Path, *, readonly: bool = False) -> None:
        self.path = Path(path)
        self.readonly = readonly
        if readonly:
            self._conn = connect_readonly(self.path)
            self._conn.row_factory = sqlite3.Row
            try:
                check_store(self._conn, self.path)
            except BaseException:
                self._conn.close()
                raise
            return
        if self.path.is_dir():
            raise NotAStoreError(f"{self.path}: is a directory, not a results database file")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        existing = self.path.is_file() and self.path.stat().st_size > 0
        try:
            self._conn = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
        except sqlite3.Error as exc:
            raise NotAStoreError(f"{self.path}: cannot open the results database ({exc})") from None
        try:
            if existing:  # never add our tables to another program's database
                tables = {
                    r[0]
                    for r in self._conn.execute("SELECT name FROM sqlite_master WHERE type='table'")
                }
                if tables and "campaigns" not in tables:
                    raise NotAStoreError(
                        f"{self.path}: not a uvnav results database (no 'campaigns' table; "
                        "written by uvnav bench / uvnav run)"
                    )
            self._conn.row_factory = sqlite3.Row
            self._conn.execute("PRAGMA journal_mode=WAL")
            self._conn.execute("PRAGMA synchronous=NORMAL")
            self._conn.execute("PRAGMA foreign_keys=ON")
            self._create_schema()
            if existing:
                check_store(self._conn, self.path)
        except sqlite3.DatabaseError as exc:
            self._conn.close()
            raise NotAStoreError(f"{self.path}: not a uvnav results database ({exc})") from None
        except BaseException:
            self._conn.close()
            raise

    # -- lifecycle

    def writer_lease(self) -> AbstractContextManager[None]:
        """This database's campaign-writer lease (:func:`writer_lease`).

        Raises:
            StoreInUseError: another process holds it.
        """
        return writer_lease(self.path)

    def close(self) -> None:
        """Close the connection (idempotent)."""
        self._conn.close()

    def __enter__(self) -> ResultsStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        if self._conn.in_transaction:  # inside batch(): its transaction holds this write
            yield self._conn
            return
        self._conn.execute("BEGIN IMMEDIATE")
        try:
            yield self._conn
        except BaseException:
            self._conn.execute("ROLLBACK")
            raise
        self._conn.execute("COMMIT")

    @contextmanager
    def batch(self) -> Iterator[None]:
        """Every write inside the block in one transaction: all of it is stored, or (on an
        exception, Ctrl-C included) none of it."""
        with self._transaction():
            yield

    def _create_schema(self) -> None:
        metric_cols = ",\n".join(f"    {m} {_metric_sql_type(m)}" for m in METRIC_NAMES)
        with self._transaction() as c:
            c.execute(
                """CREATE TABLE IF NOT EXISTS campaigns (
                    id INTEGER PRIMARY KEY,
                    name TEXT NOT NULL UNIQUE,
                    created TEXT NOT NULL,
                    config TEXT NOT NULL
                )"""
            )
            c.execute(
                f"""CREATE TABLE IF NOT EXISTS episodes (
                    id INTEGER PRIMARY KEY,
                    campaign_id INTEGER NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
                    scenario TEXT NOT NULL,
                    family TEXT NOT NULL,
                    controller TEXT NOT NULL,
                    params_hash TEXT NOT NULL,
                    params TEXT NOT NULL,
                    effective_params TEXT,
                    seed INTEGER NOT NULL,
                    status TEXT NOT NULL,
                    error TEXT,
                {metric_cols},
                    wall_time REAL,
                    created TEXT NOT NULL,
                    UNIQUE (campaign_id, scenario, controller, params_hash, seed)
                )"""
            )
            c.execute(
                """CREATE TABLE IF NOT EXISTS trajectories (
                    episode_id INTEGER PRIMARY KEY REFERENCES episodes(id) ON DELETE CASCADE,
                    data BLOB NOT NULL
                )"""
            )
            c.execute("CREATE INDEX IF NOT EXISTS episodes_campaign ON episodes(campaign_id)")
            have = {row["name"] for row in c.execute("PRAGMA table_info(episodes)")}
            for m in METRIC_NAMES:
                if m not in have:
                    c.execute(f"ALTER TABLE episodes ADD COLUMN {m} {_metric_sql_type(m)}")

    # -- campaigns

    def campaign(self, name: str, config: Mapping[str, Any] | None = None) -> int:
        """Id of campaign ``name``, created with ``config`` (stored as JSON) if it does not exist.

        An existing campaign keeps the config it was created with: a resumed campaign is identified
        by name, and the resume key of each episode decides what still has to run.
        """
        row = self._conn.execute("SELECT id FROM campaigns WHERE name = ?", (name,)).fetchone()
        if row is not None:
            return int(row["id"])
        with self._transaction() as c:
            cur = c.execute(
                "INSERT INTO campaigns (name, created, config) VALUES (?, ?, ?)",
                (name, _now(), canonical_json(dict(config or {}))),
            )
        assert cur.lastrowid is not None
        return int(cur.lastrowid)

    def campaigns(self) -> list[dict[str, Any]]:
        """All campaigns as dicts ``{id, name, created, config}`` (config decoded)."""
        rows = self._conn.execute("SELECT id, name, created, config FROM campaigns ORDER BY id")
        return [{**dict(r), "config": json.loads(r["config"])} for r in rows]

    def campaign_id(self, campaign: int | str) -> int | None:
        """Resolve a campaign name or id to its id (``None`` if it does not exist)."""
        if isinstance(campaign, int):
            row = self._conn.execute(
                "SELECT id FROM campaigns WHERE id = ?", (campaign,)
            ).fetchone()
        else:
            row = self._conn.execute(
                "SELECT id FROM campaigns WHERE name = ?", (campaign,)
            ).fetchone()
        return None if row is None else int(row["id"])

    def delete_campaign(self, campaign: int | str) -> bool:
        """Delete a campaign with its episodes and trajectories; ``False`` if it did not exist."""
        cid = self.campaign_id(campaign)
        if cid is None:
            return False
        with self._transaction() as c:
            c.execute(
                "DELETE FROM trajectories WHERE episode_id IN "
                "(SELECT id FROM episodes WHERE campaign_id = ?)",
                (cid,),
            )
            c.execute("DELETE FROM episodes WHERE campaign_id = ?", (cid,))
            c.execute("DELETE FROM campaigns WHERE id = ?", (cid,))
        return True

    # -- episodes

    def done_keys(self, campaign_id: int, *, include_errors: bool = True) -> set[EpisodeKey]:
        """Resume keys ``(scenario, controller, params_hash, seed)`` already stored for a campaign.

        Args:
            campaign_id: the campaign.
            include_errors: count ``error`` episodes as done (default); ``False`` retries them.
        """
        sql = "SELECT scenario, controller, params_hash, seed FROM episodes WHERE campaign_id = ?"
        if not include_errors:
            sql += f" AND status != '{STATUS_ERROR}'"
        rows = self._conn.execute(sql, (campaign_id,))
        return {(r[0], r[1], r[2], int(r[3])) for r in rows}

    def add_episode(
        self,
        campaign_id: int,
        *,
        scenario: str,
        controller: str,
        seed: int,
        status: str,
        params: Mapping[str, Any] | None = None,
        metrics: EpisodeMetrics | Mapping[str, Any] | None = None,
        family: str | None = None,
        effective_params: Mapping[str, Any] | None = None,
        error: str | None = None,
        wall_time: float | None = None,
        trajectory: Trajectory | None = None,
    ) -> int:
        """Store one finished episode (and its trajectory) in a single transaction.

        Args:
            campaign_id: from :meth:`campaign`.
            scenario: scenario label (built-in name, file path or generator label).
            controller: registry name, e.g. ``"zhang2019-v1"``.
            seed: episode seed.
            status: ``success``, ``collision``, ``timeout`` or ``error``.
            params: controller parameters that identify the job (hashed into the resume key).
            metrics: the episode's metrics; ``None`` (error episodes) stores NULL in every column.
            family: scenario family for reports (defaults to ``scenario``).
            effective_params: parameters the controller was actually built with, if different.
            error: error message for ``status == "error"``.
            wall_time: wall-clock time of the episode [s].
            trajectory: optional recorded trajectory, stored compressed.

        Returns:
            The episode id.

        Raises:
            sqlite3.IntegrityError: the key is already stored with a non-error status.
        """
        p = dict(params or {})
        if isinstance(metrics, EpisodeMetrics):
            mvals: Mapping[str, Any] = metrics.to_dict()
        else:
            mvals = metrics or {}
        unknown = set(mvals) - set(METRIC_NAMES)
        if unknown:
            raise ValueError(f"unknown metric(s): {', '.join(sorted(unknown))}")
        cols = [
            "campaign_id",
            "scenario",
            "family",
            "controller",
            "params_hash",
            "params",
            "effective_params",
            "seed",
            "status",
            "error",
            *METRIC_NAMES,
            "wall_time",
            "created",
        ]
        values = [
            campaign_id,
            scenario,
            family or scenario,
            controller,
            params_hash(p),
            canonical_json(p),
            None if effective_params is None else canonical_json(dict(effective_params)),
            int(seed),
            status,
            error,
            *(_sql_value(mvals.get(m)) for m in METRIC_NAMES),
            _sql_value(wall_time),
            _now(),
        ]
        key_cols = {"campaign_id", "scenario", "controller", "params_hash", "seed"}
        updates = ", ".join(f"{c} = excluded.{c}" for c in cols if c not in key_cols)
        sql = (
            f"INSERT INTO episodes ({', '.join(cols)}) VALUES ({', '.join('?' * len(cols))}) "
            "ON CONFLICT (campaign_id, scenario, controller, params_hash, seed) "
            f"DO UPDATE SET {updates} "
            f"WHERE episodes.status = '{STATUS_ERROR}' RETURNING id"
        )
        blob = trajectory_to_bytes(trajectory) if trajectory is not None else None
        with self._transaction() as c:
            row = c.execute(sql, values).fetchone()
            if row is None:
                raise sqlite3.IntegrityError(
                    f"episode {(scenario, controller, params_hash(p), seed)} already stored in "
                    f"campaign {campaign_id}"
                )
            episode_id = int(row[0])
            c.execute("DELETE FROM trajectories WHERE episode_id = ?", (episode_id,))
            if blob is not None:
                c.execute(
                    "INSERT INTO trajectories (episode_id, data) VALUES (?, ?)", (episode_id, blob)
                )
        return episode_id

    def find_episode(
        self,
        campaign: int | str,
        *,
        scenario: str,
        controller: str,
        seed: int,
        params: Mapping[str, Any] | None = None,
    ) -> int | None:
        """Id of the episode with this key, or ``None``."""
        cid = self.campaign_id(campaign)
        if cid is None:
            return None
        row = self._conn.execute(
            "SELECT id FROM episodes WHERE campaign_id = ? AND scenario = ? AND controller = ? "
            "AND params_hash = ? AND seed = ?",
            (cid, scenario, controller, params_hash(params), int(seed)),
        ).fetchone()
        return None if row is None else int(row["id"])

    def episode_row(self, episode_id: int) -> dict[str, Any]:
        """One ``episodes`` row as a dict (NULL → ``None``).

        Raises:
            KeyError: no such episode.
        """
        row = self._conn.execute("SELECT * FROM episodes WHERE id = ?", (episode_id,)).fetchone()
        if row is None:
            raise KeyError(f"no episode {episode_id}")
        return dict(row)

    def load_trajectory(self, episode_id: int) -> Trajectory | None:
        """The stored trajectory of an episode, or ``None`` if it was not recorded."""
        row = self._conn.execute(
            "SELECT data FROM trajectories WHERE episode_id = ?", (episode_id,)
        ).fetchone()
        return None if row is None else trajectory_from_bytes(bytes(row["data"]))

    def episode_result(self, episode_id: int) -> EpisodeResult:
        """Rebuild an :class:`~uvnav.sim.EpisodeResult` (metrics, status, trajectory).

        ``decision_us`` is not stored per decision; the result carries an empty array.

        Raises:
            KeyError: no such episode.
            ValueError: the episode is an ``error`` row (it has no metrics).
        """
        row = self.episode_row(episode_id)
        if row["status"] == STATUS_ERROR:
            raise ValueError(f"episode {episode_id} failed: {row['error']}")
        values: dict[str, Any] = {}
        for f in dataclasses.fields(EpisodeMetrics):
            v = row.get(f.name)
            if f.name in _BOOLEAN_METRICS:
                v = bool(v)
            elif f.name in _INTEGER_METRICS:
                v = int(v or 0)
            values[f.name] = v
        return EpisodeResult(
            metrics=EpisodeMetrics(**values),
            status=str(row["status"]),
            trajectory=self.load_trajectory(episode_id),
            decision_us=np.zeros(0),
        )

    def episodes_frame(self, campaign: int | str | None = None) -> pd.DataFrame:
        """Episodes (all, or one campaign's by id or name) with a ``campaign`` (name) column.

        ``success``/``collision`` use pandas' nullable ``boolean`` dtype; NULL metrics are missing
        values.  ``pandas.read_sql("SELECT * FROM episodes", conn)`` reads the same rows.
        """
        import pandas as pd

        sql = (
            "SELECT e.*, c.name AS campaign FROM episodes e "
            "JOIN campaigns c ON c.id = e.campaign_id"
        )
        args: tuple[Any, ...] = ()
        if campaign is not None:
            cid = self.campaign_id(campaign)
            sql += " WHERE e.campaign_id = ?"
            args = (-1 if cid is None else cid,)
        sql += " ORDER BY e.id"
        df = pd.read_sql(sql, self._conn, params=args)
        for m in METRIC_NAMES:  # an older database opened read-only lacks newer metrics
            if m not in df.columns:
                df[m] = None
        for m in _BOOLEAN_METRICS:
            df[m] = df[m].astype("boolean")
        return df

    def count(self, campaign: int | str | None = None) -> int:
        """Number of stored episodes (all, or of one campaign)."""
        if campaign is None:
            return int(self._conn.execute("SELECT COUNT(*) FROM episodes").fetchone()[0])
        cid = self.campaign_id(campaign)
        return int(
            self._conn.execute(
                "SELECT COUNT(*) FROM episodes WHERE campaign_id = ?", (cid,)
            ).fetchone()[0]
        )
