"""Real pedestrians as moving obstacles: the ETH walking-pedestrian recordings (EWAP).

Data: S. Pellegrini, A. Ess, K. Schindler, L. van Gool, "You'll never walk alone: modeling social
behavior for multi-target tracking", ICCV 2009; sequences ``seq_eth`` and ``seq_hotel`` as
redistributed in OpenTraj, shipped as package data under ``uvnav/scenarios/data/pedestrians/``
(see the ``README.md`` there for attribution and checksums).  Research use; cite the paper.

Three formats are read, all one annotation per (frame, person):

* ``obsmat`` (the ETH files): ``frame id pos_x pos_z pos_y v_x v_z v_y`` in [m] and [m/s], world
  frame, whitespace (or comma) separated; ``pos_z``/``v_z`` are the (always zero) vertical axis.
  Only the planar positions ``(pos_x, pos_y)`` are used: velocities are re-derived from the
  positions so that the replayed motion and its reported velocity agree.
* ``xy4`` (the common ``frame id x y`` files of Social-LSTM/Social-GAN/TrajNet): positions [m].
* ``trajnet`` (TrajNet++ ``.ndjson``): one JSON object a line, ``{"scene": {...}}`` (ignored) or
  ``{"track": {"f": frame, "p": id, "x": x, "y": y, ...}}``.

A hidden position (``?`` in a text file, as in TrajNet's test files, or ``null`` in ndjson) is
skipped: the file's hidden lines are counted and reported in one :class:`HiddenPositionsWarning`
naming the file, not an error.  Any other malformed line is a :class:`ScenarioError` naming the
file, the line and the problem.

After reading, :func:`shape_tracks` may scale and shift the positions (a file in pixels or in
another frame) and stitch broken tracks (:func:`stitch_tracks`: a track that ends where another
starts one annotation later is one person whose id the tracker lost).

Times are ``frame / frame_rate`` [s].  When ``frame_rate`` is not given it is inferred from the
most common frame step between consecutive annotations of one person, assuming the ETH/UCY
annotation period of :data:`ANNOTATION_PERIOD` = 0.4 s (2.5 Hz): seq_eth steps by 6 frames
(15 frames/s), seq_hotel by 10 (25 frames/s).

Replay (:class:`PedestrianReplay`): a pedestrian is present from its first to its last annotation
and its position is interpolated linearly in between (piecewise-constant velocity).  Outside that
interval it is *absent*: :meth:`PedestrianReplay.present` (and the batched
:meth:`PedestrianReplayGroup.present`) is false, and the obstacle field leaves it out of every
collision, clearance, sensing and ray-casting query (:class:`~uvnav.obstacles.ObstacleField`), so
it is never sensed, never counted in the clearance and blocks nothing.  Its stored pose is parked
at a distant point (:data:`ABSENT_DISTANCE` = 1 km from the recording's centre, each pedestrian at
its own spot) with zero velocity, which only recorded trajectories and plots see.  It appears
and disappears instantaneously; the step on which it appears reports the velocity of its first
track segment, not the jump from the parking spot (simulation collision checks are made at
integration steps, so the jump itself cannot collide).  Pedestrians do not react to the robot:
the recording is replayed as it was.
"""

from __future__ import annotations

import bisect
import gzip
import itertools
import json
import math
import warnings
import zlib
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cache
from importlib import resources
from pathlib import Path

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.obstacles import DiscBody, Obstacle, ObstacleState, Replay
from uvnav.obstacles.batch import wrap_array
from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.limits import MAX_MAGNITUDE
from uvnav.validation import coordinate_problem

#: time between two annotations of the ETH/UCY recordings [s] (2.5 Hz)
ANNOTATION_PERIOD = 0.4
#: frame rates [frames/s] of the shipped sequences (frame steps 6 and 10 per 0.4 s annotation)
DATASETS: dict[str, float] = {"eth": 15.0, "hotel": 25.0}
#: default pedestrian disc radius [m]
DEFAULT_RADIUS = 0.3
#: absent pedestrians are parked this far from the recording's centre [m] (their pose only: no
#: query sees an absent body)
ABSENT_DISTANCE = 1000.0
#: tolerance on the presence interval [s] (simulation times are sums of dt)
_TIME_EPS = 1e-9

FORMATS = ("obsmat", "xy4", "trajnet")
_COLUMNS = {"obsmat": 8, "xy4": 4}
#: default largest gap [m] between the end of a track and the start of the next for stitching
STITCH_DISTANCE = 1.0


class HiddenPositionsWarning(UserWarning):
    """A track file holds hidden positions (``?``), which were skipped."""


_DATA_PACKAGE = "uvnav.scenarios"
_DATA_DIR = "data/pedestrians"


@dataclass(frozen=True)
class Track:
    """One pedestrian's annotated path.

    Attributes:
        ped_id: the person id of the file.
        times: (n,) strictly increasing sample times [s].
        positions: (n, 2) positions [x, y] [m] at those times.
    """

    ped_id: int
    times: FloatArray
    positions: FloatArray

    def speeds(self) -> FloatArray:
        """(n - 1,) speed over each segment between annotations [m/s]."""
        if len(self.times) < 2:
            return np.zeros(0)
        return np.hypot(*np.diff(self.positions, axis=0).T) / np.diff(self.times)

    def mean_speed(self) -> float:
        """Path length over duration [m/s] (0 for a single sample)."""
        if len(self.times) < 2:
            return 0.0
        length = float(np.sum(np.hypot(*np.diff(self.positions, axis=0).T)))
        return length / float(self.times[-1] - self.times[0])


# ------------------------------------------------------------------------------------------ parsing


_Row = tuple[float, float, float, int]  # frame, x, y, line


def _parse(text: str, source: str, fmt: str, frame_rate: float | None) -> dict[int, Track]:
    if fmt not in FORMATS:
        raise ScenarioError(
            source, "", f"unknown track format {fmt!r} (one of: {', '.join(FORMATS)})"
        )
    if frame_rate is not None and not (math.isfinite(frame_rate) and frame_rate > 0):
        raise ScenarioError(source, "", f"frame_rate must be > 0 (got {frame_rate})")
    rows: dict[int, list[_Row]] = {}
    seen: set[tuple[float, int]] = set()
    hidden: list[int] = []
    entries = _json_rows(text, source) if fmt == "trajnet" else _text_rows(text, source, fmt)
    for lineno, frame, pid, x, y in entries:
        if abs(frame) > MAX_MAGNITUDE:
            raise ScenarioError(
                source, f"line {lineno}", f"frame {frame:g} is above {MAX_MAGNITUDE:g}"
            )
        if x is None or y is None:
            hidden.append(lineno)
            continue
        for axis, value in (("x", x), ("y", y)):
            problem = coordinate_problem(value)
            if problem is not None:
                raise ScenarioError(source, f"line {lineno}", f"{axis}: {problem}")
        key = (frame, pid)
        if key in seen:
            raise ScenarioError(
                source, f"line {lineno}", f"person {pid} annotated twice in frame {frame:g}"
            )
        seen.add(key)
        rows.setdefault(pid, []).append((frame, x, y, lineno))
    if hidden:
        warnings.warn(
            f"{source}: {len(hidden)} line(s) with a hidden position ('?') skipped "
            f"(first: line {hidden[0]})",
            HiddenPositionsWarning,
            stacklevel=2,
        )
    if not rows:
        raise ScenarioError(source, "", "no annotations")
    for r in rows.values():
        r.sort()
    rate = frame_rate if frame_rate is not None else _infer_frame_rate(rows, source)
    return {
        pid: Track(
            ped_id=pid,
            times=np.array([f / rate for f, _, _, _ in r]),
            positions=np.array([(x, y) for _, x, y, _ in r], dtype=float).reshape(-1, 2),
        )
        for pid, r in sorted(rows.items())
    }


_Entry = tuple[int, float, int, float | None, float | None]  # line, frame, id, x, y (None: hidden)


def _number(text: str, source: str, where: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ScenarioError(source, where, f"not a number: {text!r} ({what})") from None
    if not math.isfinite(value):
        raise ScenarioError(source, where, f"non-finite number {text!r} ({what})")
    return value


def _person(value: float, text: str, source: str, where: str) -> int:
    if not value.is_integer():
        raise ScenarioError(source, where, f"person id must be an integer (got {text})")
    return int(value)


def _text_rows(text: str, source: str, fmt: str) -> list[_Entry]:
    ncol = _COLUMNS[fmt]
    xcol, ycol = (2, 4) if fmt == "obsmat" else (2, 3)
    out: list[_Entry] = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].replace(",", " ").strip()
        if not line:
            continue
        parts = line.split()
        where = f"line {lineno}"
        if len(parts) != ncol:
            raise ScenarioError(
                source, where, f"expected {ncol} columns for {fmt} (got {len(parts)})"
            )
        frame = _number(parts[0], source, where, "frame")
        pid = _person(_number(parts[1], source, where, "person id"), parts[1], source, where)
        if parts[xcol] == "?" or parts[ycol] == "?":
            out.append((lineno, frame, pid, None, None))
            continue
        for j, p in enumerate(parts[2:], start=2):
            if p != "?":
                _number(p, source, where, f"column {j + 1}")
        x = _number(parts[xcol], source, where, "x")
        y = _number(parts[ycol], source, where, "y")
        out.append((lineno, frame, pid, x, y))
    return out


def _json_rows(text: str, source: str) -> list[_Entry]:
    out: list[_Entry] = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        where = f"line {lineno}"
        try:
            obj = json.loads(line)
        except json.JSONDecodeError as exc:
            raise ScenarioError(
                source, where, f"not JSON: {exc.msg} (column {exc.colno})"
            ) from None
        if not isinstance(obj, dict) or not ({"scene", "track"} & set(obj)):
            raise ScenarioError(
                source, where, 'expected {"scene": {...}} or {"track": {...}} (TrajNet++ ndjson)'
            )
        if "track" not in obj:
            continue
        tr = obj["track"]
        if not isinstance(tr, dict):
            raise ScenarioError(source, where, "track must be an object {f, p, x, y}")
        missing = [k for k in ("f", "p", "x", "y") if k not in tr]
        if missing:
            raise ScenarioError(source, where, f"track lacks {', '.join(missing)}")
        vals: list[float | None] = []
        for k in ("f", "p", "x", "y"):
            v = tr[k]
            if k in "xy" and (v is None or v == "?"):
                vals.append(None)
            elif isinstance(v, bool) or not isinstance(v, int | float | str):
                raise ScenarioError(source, where, f"track.{k} is not a number: {v!r}")
            else:
                vals.append(_number(str(v), source, where, f"track.{k}"))
        frame, pid = vals[0], vals[1]
        assert frame is not None and pid is not None
        out.append((lineno, frame, _person(pid, str(tr["p"]), source, where), vals[2], vals[3]))
    return out


def _infer_frame_rate(rows: dict[int, list[_Row]], source: str) -> float:
    steps: Counter[float] = Counter()
    for r in rows.values():
        steps.update(round(b[0] - a[0], 6) for a, b in itertools.pairwise(r))
    if not steps:
        raise ScenarioError(
            source, "", "cannot infer frame_rate: no person has two annotations; give frame_rate"
        )
    step = steps.most_common(1)[0][0]
    return step / ANNOTATION_PERIOD


def read_tracks(
    path: str | Path, fmt: str = "obsmat", *, frame_rate: float | None = None
) -> dict[int, Track]:
    """Tracks of a file in format ``fmt`` (``obsmat``, ``xy4`` or ``trajnet``); ``.gz`` files are
    decompressed.

    Raises:
        ScenarioError: missing/unreadable file or bad contents (one line).
    """
    p = Path(path)
    source = str(path)
    try:
        if p.exists() and not p.is_file():  # a FIFO or /dev/zero would never end
            raise ScenarioError(source, "", "is not a regular file")
        data = p.read_bytes()
    except FileNotFoundError:
        raise ScenarioError(source, "", "no such file") from None
    except OSError as exc:
        raise ScenarioError(source, "", f"cannot read: {exc.strerror or exc}") from None
    return _parse(_decode(data, source, p.name), source, fmt, frame_rate)


def _decode(data: bytes, source: str, name: str) -> str:
    try:
        if name.endswith(".gz"):
            data = gzip.decompress(data)
        return data.decode("utf-8")
    except (OSError, EOFError, UnicodeDecodeError, zlib.error) as exc:
        raise ScenarioError(source, "", f"cannot decode: {exc}") from None


@cache
def load_dataset(name: str) -> dict[int, Track]:
    """Tracks of a shipped sequence, ``"eth"`` or ``"hotel"`` (cached; do not mutate).

    Raises:
        ScenarioError: unknown name.
    """
    if name not in DATASETS:
        raise ScenarioError(name, "", f"unknown pedestrian dataset (known: {', '.join(DATASETS)})")
    entry = resources.files(_DATA_PACKAGE).joinpath(_DATA_DIR, name, "obsmat.txt.gz")
    source = f"{_DATA_DIR}/{name}/obsmat.txt.gz"
    return _parse(_decode(entry.read_bytes(), source, entry.name), source, "obsmat", DATASETS[name])


@cache
def _cached_file(
    path: str, fmt: str, frame_rate: float | None, stamp: tuple[int, int]
) -> dict[int, Track]:
    return read_tracks(path, fmt, frame_rate=frame_rate)


def load_tracks(
    dataset: str,
    fmt: str = "obsmat",
    *,
    frame_rate: float | None = None,
    scale: float = 1.0,
    offset: tuple[float, float] = (0.0, 0.0),
    stitch: bool = False,
) -> dict[int, Track]:
    """Tracks of a shipped dataset name (``eth``, ``hotel``) or of a file path (cached by path,
    modification time and size), shaped by :func:`shape_tracks` (``scale``, ``offset``,
    ``stitch``).  A shipped name ignores ``fmt``; ``frame_rate`` overrides its rate when given."""
    if dataset in DATASETS:
        stamp = None
    else:
        p = Path(dataset)
        try:
            st = p.stat()
        except OSError:
            raise ScenarioError(
                dataset, "", f"no such file or shipped dataset ({', '.join(DATASETS)})"
            ) from None
        dataset = str(p.resolve())
        stamp = (st.st_mtime_ns, st.st_size)
    off = (float(offset[0]), float(offset[1]))
    return _shaped(dataset, fmt, frame_rate, float(scale), off, bool(stitch), stamp)


@cache
def _shaped(
    dataset: str,
    fmt: str,
    frame_rate: float | None,
    scale: float,
    offset: tuple[float, float],
    stitch: bool,
    stamp: tuple[int, int] | None,
) -> dict[int, Track]:
    if stamp is None:  # shipped
        base = load_dataset(dataset)
        if frame_rate is not None and frame_rate != DATASETS[dataset]:
            k = DATASETS[dataset] / frame_rate
            base = {i: Track(i, t.times * k, t.positions) for i, t in base.items()}
    else:
        base = _cached_file(dataset, fmt, frame_rate, stamp)
    return shape_tracks(base, scale=scale, offset=offset, stitch=stitch)


def shape_tracks(
    tracks: dict[int, Track],
    *,
    scale: float = 1.0,
    offset: tuple[float, float] = (0.0, 0.0),
    stitch: bool = False,
) -> dict[int, Track]:
    """``tracks`` with positions ``scale * p + offset`` [m] and, with ``stitch``, broken tracks
    joined (:func:`stitch_tracks`).  The defaults return ``tracks`` itself."""
    if not (math.isfinite(scale) and scale > 0):
        raise ScenarioError("", "scale", f"must be > 0 (got {scale})")
    out = tracks
    if scale != 1.0 or offset != (0.0, 0.0):
        shift = np.asarray(offset, dtype=float)
        out = {i: Track(i, t.times, t.positions * scale + shift) for i, t in out.items()}
        reach = max((float(np.abs(t.positions).max()) for t in out.values()), default=0.0)
        problem = coordinate_problem(reach)
        if problem is not None:
            raise ScenarioError("", "scale", f"a position scale * p + offset of {problem}")
    if stitch:
        out = stitch_tracks(out)
    return out


def annotation_step(tracks: dict[int, Track]) -> float:
    """The most common time between consecutive annotations of one person [s] (the recording's
    annotation period; :data:`ANNOTATION_PERIOD` when no track has two samples)."""
    steps: Counter[float] = Counter()
    for t in tracks.values():
        steps.update(np.round(np.diff(t.times), 9).tolist())
    return float(steps.most_common(1)[0][0]) if steps else ANNOTATION_PERIOD


def stitch_tracks(
    tracks: dict[int, Track],
    *,
    max_gap: float | None = None,
    max_distance: float = STITCH_DISTANCE,
) -> dict[int, Track]:
    """Join the pieces of one person that a tracker gave several ids.

    Track B continues track A when B starts after A ends by at most ``max_gap`` [s] (default: one
    annotation step, :func:`annotation_step`, i.e. B starts at most one annotated frame after A's
    last) and within ``max_distance`` [m] of A's last position.  Candidate pairs are taken
    closest first; each track continues at most one and is continued by at most one, so chains
    A -> B -> C become one track.  The joined track keeps the first piece's id and is
    interpolated across the gap, so the person neither vanishes nor pops up beside the robot.

    Returns:
        ``{id: Track}`` sorted by id (the continued ids are gone).
    """
    gap = annotation_step(tracks) if max_gap is None else float(max_gap)
    eps = 1e-9 * max(1.0, gap)
    by_start = sorted(tracks.values(), key=lambda t: (float(t.times[0]), t.ped_id))
    starts = [float(t.times[0]) for t in by_start]
    pairs: list[tuple[float, float, int, int]] = []
    for a in tracks.values():
        end = float(a.times[-1])
        lo = bisect.bisect_right(starts, end + eps)
        hi = bisect.bisect_right(starts, end + gap + eps)
        for b in by_start[lo:hi]:
            if b.ped_id == a.ped_id:
                continue
            d = float(np.hypot(*(b.positions[0] - a.positions[-1])))
            if d <= max_distance:
                pairs.append((d, float(b.times[0]) - end, a.ped_id, b.ped_id))
    nxt: dict[int, int] = {}
    prev: dict[int, int] = {}
    for _, _, a_id, b_id in sorted(pairs):
        if a_id not in nxt and b_id not in prev:
            nxt[a_id] = b_id
            prev[b_id] = a_id
    if not nxt:
        return tracks
    out: dict[int, Track] = {}
    for pid in sorted(tracks):
        if pid in prev:
            continue
        chain = [tracks[pid]]
        while chain[-1].ped_id in nxt:
            chain.append(tracks[nxt[chain[-1].ped_id]])
        if len(chain) == 1:
            out[pid] = chain[0]
        else:
            out[pid] = Track(
                pid,
                np.concatenate([c.times for c in chain]),
                np.concatenate([c.positions for c in chain]),
            )
    return out


# ---------------------------------------------------------------------------------------- geometry


def all_positions(tracks: dict[int, Track]) -> FloatArray:
    """(N, 2) every annotated position [m]."""
    return np.concatenate([t.positions for t in tracks.values()])


def walkway_axes(tracks: dict[int, Track]) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(centre, along, across)``: the mean position [m] and unit vectors of the principal axis of
    all annotated positions (the walkway's main direction) and of the perpendicular axis."""
    pts = all_positions(tracks)
    centre = pts.mean(axis=0)
    _, vecs = np.linalg.eigh(np.cov((pts - centre).T))
    along = vecs[:, 1] * (1.0 if vecs[0, 1] + vecs[1, 1] >= 0 else -1.0)
    across = np.array([-along[1], along[0]])
    return centre, along, across


# ------------------------------------------------------------------------------------------ replay


@dataclass
class PedestrianReplay(Replay):
    """A pedestrian's recorded path, present only between its first and last sample.

    Inside ``[times[0], times[-1]]`` [s] positions are interpolated linearly (velocity piecewise
    constant, heading along the course), exactly as :class:`~uvnav.obstacles.Replay`; outside it
    the pedestrian is parked at ``absent`` [m] with zero velocity (see the module docstring).

    Attributes:
        times: (m,) strictly increasing sample times [s], m >= 2.
        positions: (m, 2) positions [m].
        absent: (2,) parking position while absent [m].
    """

    absent: FloatArray = field(default_factory=lambda: np.full(2, ABSENT_DISTANCE))
    _t: list[float] = field(default_factory=list, init=False, repr=False)
    _x: list[float] = field(default_factory=list, init=False, repr=False)
    _y: list[float] = field(default_factory=list, init=False, repr=False)

    def __post_init__(self) -> None:
        self.times = np.asarray(self.times, dtype=float)
        self.positions = np.asarray(self.positions, dtype=float).reshape(-1, 2)
        self.absent = np.asarray(self.absent, dtype=float)
        if len(self.times) < 2 or len(self.times) != len(self.positions):
            raise ValueError("need >= 2 samples, one position per time")
        if np.any(np.diff(self.times) <= 0):
            raise ValueError("times must be strictly increasing")
        self._t = self.times.tolist()
        self._x = self.positions[:, 0].tolist()
        self._y = self.positions[:, 1].tolist()

    def present(self, t: float) -> bool:
        """Whether the pedestrian is on the scene at time ``t`` [s]."""
        return self._t[0] - _TIME_EPS <= t <= self._t[-1] + _TIME_EPS

    def _segment(self, t: float) -> int:
        return min(max(bisect.bisect_right(self._t, t) - 1, 0), len(self._t) - 2)

    def position_at(self, t: float) -> FloatArray:
        """Position [m] at ``t`` [s]: interpolated while present, ``absent`` otherwise."""
        if not self.present(t):
            return self.absent.copy()
        k = self._segment(t)
        t0, t1 = self._t[k], self._t[k + 1]
        s = min(max((t - t0) / (t1 - t0), 0.0), 1.0)
        if s == 0.0:
            return np.array([self._x[k], self._y[k]])
        if s == 1.0:
            return np.array([self._x[k + 1], self._y[k + 1]])
        return np.array(
            [
                self._x[k] + s * (self._x[k + 1] - self._x[k]),
                self._y[k] + s * (self._y[k + 1] - self._y[k]),
            ]
        )

    def velocity_at(self, t: float) -> FloatArray:
        """Velocity [m/s] of the track segment containing ``t`` [s] (zero while absent)."""
        if not self.present(t):
            return np.zeros(2)
        k = self._segment(t)
        dt = self._t[k + 1] - self._t[k]
        return np.array([(self._x[k + 1] - self._x[k]) / dt, (self._y[k + 1] - self._y[k]) / dt])

    def initial_state(self, t: float = 0.0) -> ObstacleState:
        """State at ``t`` [s]: position, segment velocity, heading along it."""
        vel = self.velocity_at(t)
        heading = float(math.atan2(vel[1], vel[0])) if math.hypot(*vel) > 1e-9 else 0.0
        return ObstacleState(position=self.position_at(t), heading=heading, velocity=vel)

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState:
        t1 = t + dt
        if not self.present(t1):
            return ObstacleState(
                position=self.absent.copy(), heading=state.heading, velocity=np.zeros(2)
            )
        new = self.position_at(t1)
        # appearing: report the track's velocity, not the jump from the parking spot
        velocity = (new - state.position) / dt if self.present(t) else self.velocity_at(t1)
        heading = state.heading
        if math.hypot(velocity[0], velocity[1]) > 1e-9:
            heading = float(math.atan2(velocity[1], velocity[0]))
        omega = wrap_scalar(heading - state.heading) / dt if self.present(t) else 0.0
        return ObstacleState(
            position=new, heading=heading, velocity=velocity, angular_velocity=omega
        )

    @classmethod
    def batch_group(cls, models: Sequence[PedestrianReplay]) -> PedestrianReplayGroup:
        """All of an episode's pedestrians advanced together (see
        :class:`~uvnav.obstacles.motion.MotionGroup`)."""
        return PedestrianReplayGroup(models)

    def speed_bound(self) -> float:
        """Largest segment speed of the track [m/s] (the parking jumps do not count)."""
        return float(np.max(np.hypot(*np.diff(self.positions, axis=0).T) / np.diff(self.times)))


# ------------------------------------------------------------------------------------- episodes


def episode_tracks(
    tracks: dict[int, Track],
    *,
    t_start: float,
    duration: float,
    region: tuple[float, float, float, float] | None = None,
    at_rest: bool = False,
) -> list[Track]:
    """The pieces of ``tracks`` seen in the episode window, times shifted so ``t_start`` is 0.

    With ``region = [xmin, ymin, xmax, ymax]`` [m] only samples inside it are kept, and a track that
    leaves and re-enters gives one piece per visit.  Pieces with fewer than two samples are dropped
    (a pedestrian seen once has no motion to replay).  A piece is kept when its time span overlaps
    ``[0, duration]``; samples outside the window are kept too, so the interpolation at the window
    edges uses the real neighbouring annotations.

    With ``at_rest`` a person whose first piece starts after t = 0 waits at rest (present, zero
    velocity) at that piece's first position from t = 0 on, instead of appearing out of nowhere
    when its annotations begin (a sample at t = 0 is prepended).
    """
    out: list[Track] = []
    for pid, tr in tracks.items():
        times = tr.times - t_start
        pos = tr.positions
        if times[-1] < -_TIME_EPS or times[0] > duration + _TIME_EPS:
            continue
        if region is None:
            runs = [np.arange(len(times))]
        else:
            x0, y0, x1, y1 = region
            inside = (pos[:, 0] >= x0) & (pos[:, 0] <= x1) & (pos[:, 1] >= y0) & (pos[:, 1] <= y1)
            idx = np.flatnonzero(inside)
            runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if idx.size else []
        first = True
        for run in runs:
            if len(run) < 2:
                continue
            tt = times[run]
            if tt[-1] < -_TIME_EPS or tt[0] > duration + _TIME_EPS:
                continue
            pp = pos[run]
            if at_rest and first and tt[0] > _TIME_EPS:
                tt = np.concatenate(([0.0], tt))
                pp = np.concatenate((pp[:1], pp))
            first = False
            out.append(Track(ped_id=pid, times=tt, positions=pp))
    return out


def crowd_obstacles(
    pieces: list[Track], *, radius: float = DEFAULT_RADIUS, centre: FloatArray | None = None
) -> list[Obstacle]:
    """Disc obstacles replaying ``pieces`` (from :func:`episode_tracks`), named ``ped-<id>``.

    Args:
        pieces: episode-time tracks.
        radius: pedestrian disc radius [m].
        centre: centre of the recording [m]; absent pedestrians are parked
            :data:`ABSENT_DISTANCE` m from it, one metre apart from each other.
    """
    c = np.zeros(2) if centre is None else np.asarray(centre, dtype=float)
    names: Counter[int] = Counter()
    out: list[Obstacle] = []
    for j, tr in enumerate(pieces):
        parked = c + np.array([ABSENT_DISTANCE + float(j), 0.0])
        motion = PedestrianReplay(tr.times, tr.positions, absent=parked)
        k = names[tr.ped_id]
        names[tr.ped_id] += 1
        name = f"ped-{tr.ped_id}" + (f".{k}" if k else "")
        out.append(
            Obstacle(
                body=DiscBody(float(radius)),
                state=motion.initial_state(0.0),
                motion=motion,
                name=name,
            )
        )
    return out


def crowd_speed_stats(pieces: list[Track], duration: float) -> tuple[float, float]:
    """``(typical, max)`` walking speed [m/s] of the pedestrians in the window ``[0, duration]``.

    ``typical`` is the time-weighted mean speed (every pedestrian-second in the window counts the
    same, standing people included: the dataset README's "mean walking speed"), ``max`` the largest
    segment speed.  Both zero without pieces.
    """
    lengths = 0.0
    total = 0.0
    top = 0.0
    for tr in pieces:
        lo = np.clip(tr.times[:-1], 0.0, duration)
        hi = np.clip(tr.times[1:], 0.0, duration)
        w = hi - lo
        if not np.any(w > 0):
            continue
        sp = tr.speeds()
        lengths += float(np.sum(sp * w))
        total += float(np.sum(w))
        top = max(top, float(np.max(sp[w > 0])))
    if total <= 0.0:
        return 0.0, 0.0
    return lengths / total, top


class PedestrianReplayGroup:
    """:meth:`PedestrianReplay.step` for many pedestrians at once, as arrays.

    The tracks are packed into (m, L) arrays padded with +inf times, so a step costs a few array
    operations whatever the number of pedestrians (a crowd scene has 50–100).  Every number is
    computed with the scalar method's operations in the same order, so the results are bit for bit
    those of calling ``step`` on each pedestrian (the test suite checks it).
    """

    def __init__(self, models: Sequence[PedestrianReplay]) -> None:
        m = len(models)
        width = max((len(r.times) for r in models), default=2)
        self._t = np.full((m, width), np.inf)
        self._x = np.zeros((m, width))
        self._y = np.zeros((m, width))
        self._last_seg = np.empty(m, dtype=np.intp)
        for i, r in enumerate(models):
            n = len(r.times)
            self._t[i, :n] = r.times
            self._x[i, :n] = r.positions[:, 0]
            self._y[i, :n] = r.positions[:, 1]
            self._last_seg[i] = n - 2
        self._first = self._t[:, 0] - _TIME_EPS
        self._end = self._t[np.arange(m), self._last_seg + 1] + _TIME_EPS
        self._absent = np.array([r.absent for r in models], dtype=float).reshape(m, 2).T
        self._rows = np.arange(m)

    def _present(self, t: float) -> np.ndarray:
        return (self._first <= t) & (t <= self._end)

    def present(self, t: float) -> np.ndarray:
        """(m,) whether each pedestrian is on the scene at ``t`` [s]
        (:meth:`PedestrianReplay.present`, element by element)."""
        return self._present(t)

    def step(
        self, position: FloatArray, heading: FloatArray, t: float, dt: float
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """See :meth:`uvnav.obstacles.motion.MotionGroup.step`."""
        t1 = t + dt
        was = self._present(t)
        now = self._present(t1)
        seg = np.count_nonzero(self._t <= t1, axis=1) - 1
        seg = np.minimum(np.maximum(seg, 0), self._last_seg)
        rows = self._rows
        ta = self._t[rows, seg]
        tb = self._t[rows, seg + 1]
        xa, xb = self._x[rows, seg], self._x[rows, seg + 1]
        ya, yb = self._y[rows, seg], self._y[rows, seg + 1]
        with np.errstate(invalid="ignore", divide="ignore"):
            s = np.minimum(np.maximum((t1 - ta) / (tb - ta), 0.0), 1.0)
            new = np.stack(
                (
                    np.where(s == 1.0, xb, xa + s * (xb - xa)),
                    np.where(s == 1.0, yb, ya + s * (yb - ya)),
                )
            )
            span = tb - ta
            track_v = np.stack(((xb - xa) / span, (yb - ya) / span))
        new = np.where(now, new, self._absent)
        vel = np.where(was, (new - position) / dt, track_v)
        vel = np.where(now, vel, 0.0)
        moving = (np.hypot(vel[0], vel[1]) > 1e-9).nonzero()[0]
        new_heading = np.array(heading, dtype=float)
        # math.atan2, as the scalar step: numpy's vectorised arctan2 may differ in the last bit
        vx, vy = vel[0, moving].tolist(), vel[1, moving].tolist()
        new_heading[moving] = [math.atan2(b, a) for a, b in zip(vx, vy, strict=True)]
        diff = new_heading - heading
        omega = np.where(was & now, wrap_array(diff) / dt, 0.0)
        return new, new_heading, vel, omega
