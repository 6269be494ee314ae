"""Udacity-layout driving data: ``driving_log.csv`` + ``IMG/``, balancing and the 8:2 split.

Thesis Chapter 6 §6.3: 17,592 frames from the Udacity simulator's three cameras with steering and
throttle (Fig. 6.1); the steering histogram (Fig. 6.4), balancing with a threshold of 200 samples
per bin (Fig. 6.5), a random 8:2 training/validation split (Fig. 6.6).

The layout is Udacity's ``self-driving-car-sim`` recorder's: one CSV row per time step, no
header, columns ``center, left, right, steering, throttle, brake, speed`` with image paths that
may be absolute (Windows or POSIX) from the recording machine — the loader resolves them by file
name under ``IMG/`` next to the CSV, so real Udacity recordings and ours load the same way.
Left/right images are used as extra samples with steering ``± correction`` (0.2 by default, the
usual value for the Udacity car): the left camera sees the car as if it were left of where it is,
so its label steers more to the right (+).

Udacity's speed column is in mph; ours is CarRacing's [m/s] (the writer records what it is given).

One optional column beyond Udacity's seven: ``target_speed`` [m/s], the speed the expert is
tracking at that row (the minimum of its corner-speed profile over the preview distance,
:meth:`uvnav.driving.expert.PurePursuitExpert.target_speed`).  It is a function of the road ahead,
hence observable from one forward image, unlike the expert's throttle, which also depends on the
speed; the "learned-speed" throttle trains the network's second output on it.  Rows without it
(real Udacity logs, datasets recorded before the column existed) load as before, with NaN there.

Two more optional columns (ours only, beyond the thesis): ``steering_left, steering_right``, the
exact labels of the left and right images — the expert's command at the pose the side camera
sees (:meth:`uvnav.driving.expert.PurePursuitExpert.side_steering`).  A row then has 10 columns
(``target_speed`` is written as ``nan`` if unknown).  :func:`expand_cameras` uses them where a
row has them and the fixed ``± correction`` elsewhere.  Measured in thesis-size runs
(docs/thesis-notes.md, Chapter 6): with the fixed 0.2 the side images' validation steering MSE
was 0.065 / 0.085 against 0.035 on centre images; with exact labels the three cameras are alike
(0.056–0.059).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

LOG_NAME = "driving_log.csv"
IMG_DIR = "IMG"
COLUMNS = ("center", "left", "right", "steering", "throttle", "brake", "speed")
#: optional columns after Udacity's seven (ours only): a row has 7, 8 or all 10
EXTRA_COLUMNS = ("target_speed", "steering_left", "steering_right")
#: camera of each sample in :class:`Samples` (``Samples.camera``)
CAMERA_CENTRE, CAMERA_LEFT, CAMERA_RIGHT = 0, 1, 2
CAMERA_NAMES = ("centre", "left", "right")


#: largest image (width x height) a driving log may hold; a module constant
MAX_IMAGE_PIXELS = 4096 * 4096


class DatasetError(ValueError):
    """A malformed dataset: one line naming the file, the row/field and the problem."""


@dataclass(frozen=True)
class DrivingLog:
    """The rows of a ``driving_log.csv`` (paths resolved to existing files under ``IMG/``).

    Attributes:
        root: dataset folder.
        center: centre image paths.
        left: left image paths.
        right: right image paths.
        steering: steering in [-1, 1] (+ right).
        throttle: throttle (Udacity: [0, 1]; ours: [-1, 1], negative = brake).
        brake: brake in [0, 1].
        speed: speed (Udacity [mph], ours [m/s]).
        target_speed: the expert's target speed [m/s] (optional 8th column; NaN where a row
            has none, ``None`` when no row has it, e.g. a real Udacity log).
        steering_left: exact label of the left image (optional 9th column; NaN where a row has
            none, ``None`` when no row has it).
        steering_right: exact label of the right image (10th column; as ``steering_left``).
    """

    root: Path
    center: list[Path]
    left: list[Path]
    right: list[Path]
    steering: NDArray[np.float64]
    throttle: NDArray[np.float64]
    brake: NDArray[np.float64]
    speed: NDArray[np.float64]
    target_speed: NDArray[np.float64] | None = None
    steering_left: NDArray[np.float64] | None = None
    steering_right: NDArray[np.float64] | None = None

    def __len__(self) -> int:
        return len(self.center)


@dataclass(frozen=True)
class Samples:
    """Flat training samples: one image path per sample and its labels.

    ``target_speed`` [m/s] is the expert's target speed (NaN where the log has none);
    ``camera`` is the camera of each sample (:data:`CAMERA_CENTRE`, :data:`CAMERA_LEFT`,
    :data:`CAMERA_RIGHT`; ``None``: not known).
    """

    paths: list[Path]
    steering: NDArray[np.float64]
    throttle: NDArray[np.float64]
    speed: NDArray[np.float64]
    target_speed: NDArray[np.float64] | None = None
    camera: NDArray[np.int8] | None = None

    def __len__(self) -> int:
        return len(self.paths)

    def take(self, idx: NDArray[np.int64]) -> Samples:
        """The samples at ``idx``."""
        return Samples(
            [self.paths[int(i)] for i in idx],
            self.steering[idx],
            self.throttle[idx],
            self.speed[idx],
            None if self.target_speed is None else self.target_speed[idx],
            None if self.camera is None else self.camera[idx],
        )


def _resolve(root: Path, raw: str, log: Path, row: int, col: str) -> Path:
    raw = raw.strip()
    if not raw:
        raise DatasetError(f"{log}: row {row}, column '{col}': empty image path")
    name = raw.replace("\\", "/").split("/")[-1]
    for cand in (root / IMG_DIR / name, root / raw):
        if cand.is_file():
            return cand
    raise DatasetError(f"{log}: row {row}, column '{col}': image '{name}' not found in {IMG_DIR}/")


def read_log(root: Path | str, *, check_images: bool = True) -> DrivingLog:
    """Read a Udacity-layout dataset folder.

    Args:
        root: folder holding ``driving_log.csv`` and ``IMG/``.
        check_images: resolve every path to an existing file (else keep ``IMG/<name>``).

    Returns:
        The log.

    Rows have Udacity's seven columns, eight with our ``target_speed`` or ten with the exact
    side labels too (they may be mixed in one log, e.g. a Udacity recording extended by DAgger
    rows; absent values are NaN).

    Raises:
        DatasetError: missing CSV, wrong column count, non-numeric value, NaN or ±inf where a
            finite number is meant (``nan`` is allowed only in the optional columns, where it
            means "no value"), missing image.
    """
    root = Path(root)
    log = root / LOG_NAME
    if not log.is_file():
        raise DatasetError(f"{log}: not found (a dataset folder holds {LOG_NAME} and {IMG_DIR}/)")
    cols: dict[str, list[object]] = {c: [] for c in COLUMNS}
    extra: dict[str, list[float]] = {c: [] for c in EXTRA_COLUMNS}
    n_all = len(COLUMNS) + len(EXTRA_COLUMNS)
    allowed = (len(COLUMNS), len(COLUMNS) + 1, n_all)
    try:
        text = log.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise DatasetError(
            f"{log}: not a text (CSV) file (byte {exc.start} is not UTF-8)"
        ) from None
    if "\x00" in text:
        raise DatasetError(f"{log}: not a text (CSV) file (it holds NUL bytes)")
    with io.StringIO(text, newline="") as fh:
        for r, rec in enumerate(csv.reader(fh), start=1):
            if not rec or all(not x.strip() for x in rec):
                continue
            if r == 1 and rec[0].strip().lower() == "center":
                continue  # header (some Udacity sample sets have one)
            if len(rec) not in allowed:
                raise DatasetError(
                    f"{log}: row {r}: {len(rec)} columns (expected {len(COLUMNS)}: "
                    f"{', '.join(COLUMNS)}; {len(COLUMNS) + 1} with {EXTRA_COLUMNS[0]}; or "
                    f"{n_all} with {', '.join(EXTRA_COLUMNS)})"
                )
            for c, x in zip(COLUMNS[:3], rec[:3], strict=True):
                cols[c].append(
                    _resolve(root, x, log, r, c)
                    if check_images
                    else root / IMG_DIR / x.strip().replace("\\", "/").split("/")[-1]
                )
            for c, x in zip(COLUMNS[3:], rec[3:7], strict=True):
                cols[c].append(_number(x, log, r, c))
            for j, c in enumerate(EXTRA_COLUMNS, start=len(COLUMNS)):
                value = _number(rec[j], log, r, c, missing=True) if len(rec) > j else math.nan
                extra[c].append(value)
    if not cols["center"]:
        raise DatasetError(f"{log}: no rows")
    ts, sl, sr = (_optional(extra[c]) for c in EXTRA_COLUMNS)
    return DrivingLog(
        root,
        [Path(str(p)) for p in cols["center"]],
        [Path(str(p)) for p in cols["left"]],
        [Path(str(p)) for p in cols["right"]],
        np.asarray(cols["steering"], dtype=float),
        np.asarray(cols["throttle"], dtype=float),
        np.asarray(cols["brake"], dtype=float),
        np.asarray(cols["speed"], dtype=float),
        ts,
        sl,
        sr,
    )


def _optional(values: list[float]) -> NDArray[np.float64] | None:
    """An optional column: ``None`` when no row has a value."""
    a = np.asarray(values, dtype=float)
    return None if np.isnan(a).all() else a


#: the physical range of each numeric column (steering and throttle are normalised commands,
#: brake a pedal in [0, 1], speeds [m/s] or [mph]); a value outside is a broken log, not a label
COLUMN_RANGES = {
    "steering": (-1.0, 1.0),
    "throttle": (-1.0, 1.0),
    "brake": (0.0, 1.0),
    "speed": (-1000.0, 1000.0),
    "target_speed": (0.0, 1000.0),
    "steering_left": (-1.0, 1.0),
    "steering_right": (-1.0, 1.0),
}
#: rounding slack of the written labels at the ends of their ranges
_SLACK = 1e-6


def _number(x: str, log: Path, row: int, col: str, *, missing: bool = False) -> float:
    """One CSV field as a finite float within its :data:`COLUMN_RANGES` range (``missing``:
    ``nan`` is allowed, meaning "no value").

    Raises:
        DatasetError: not a number, not finite (``nan`` where a value is required, ``±inf``), or
            outside the column's range.
    """
    try:
        value = float(x)
    except ValueError:
        raise DatasetError(f"{log}: row {row}, column '{col}': {x!r} is not a number") from None
    lo, hi = COLUMN_RANGES[col]
    if math.isfinite(value) and not lo - _SLACK <= value <= hi + _SLACK:
        raise DatasetError(
            f"{log}: row {row}, column '{col}': {value:g} is outside its range [{lo:g}, {hi:g}]"
        )
    if math.isfinite(value) or (missing and math.isnan(value)):
        return value
    raise DatasetError(
        f"{log}: row {row}, column '{col}': {x.strip()!r} is not a finite number"
        + ("" if missing else " (a value is required)")
    )


class LogWriter:
    """Append rows and images to a Udacity-layout dataset (resumable: appends to an existing log).

    Images are written as ``IMG/{camera}_{key}.jpg`` (Udacity's naming idea, our keys) and the CSV
    holds paths relative to the dataset folder.
    """

    def __init__(self, root: Path | str) -> None:
        self.root = Path(root)
        (self.root / IMG_DIR).mkdir(parents=True, exist_ok=True)
        self._fh = (self.root / LOG_NAME).open("a", newline="")
        self._csv = csv.writer(self._fh)

    def write(
        self,
        key: str,
        images: Sequence[NDArray[np.uint8]],
        *,
        steering: float,
        throttle: float,
        brake: float,
        speed: float,
        target_speed: float | None = None,
        side_steering: tuple[float, float] | None = None,
    ) -> None:
        """Write one row: ``images`` = (center, left, right) uint8 RGB arrays.

        ``target_speed`` [m/s] (the expert's), when given, is written as an 8th column;
        ``side_steering`` (exact labels of the left and right images), when given, as the 9th
        and 10th (with ``nan`` in the 8th if there is no target speed).
        """
        from PIL import Image

        labels = {"steering": steering, "throttle": throttle, "brake": brake, "speed": speed}
        if target_speed is not None:
            labels["target_speed"] = target_speed
        if side_steering is not None:
            labels["steering_left"], labels["steering_right"] = side_steering
        bad = next((k for k, v in labels.items() if not math.isfinite(v)), None)
        if bad is not None:
            raise DatasetError(
                f"{self.root / LOG_NAME}: row {key!r}, column '{bad}': {labels[bad]} is not a "
                "finite number (not written)"
            )
        names = []
        for cam, img in zip(("center", "left", "right"), images, strict=True):
            name = f"{IMG_DIR}/{cam}_{key}.jpg"
            Image.fromarray(np.asarray(img, dtype=np.uint8)).save(self.root / name, quality=95)
            names.append(name)
        row = [*names, f"{steering:.6f}", f"{throttle:.6f}", f"{brake:.6f}", f"{speed:.6f}"]
        if target_speed is not None or side_steering is not None:
            row.append("nan" if target_speed is None else f"{target_speed:.6f}")
        if side_steering is not None:
            row += [f"{side_steering[0]:.6f}", f"{side_steering[1]:.6f}"]
        self._csv.writerow(row)

    def flush(self) -> None:
        """Flush the CSV (call at episode ends: a killed run keeps whole episodes)."""
        self._fh.flush()

    def close(self) -> None:
        """Close the CSV."""
        self._fh.close()


def expand_cameras(
    log: DrivingLog, *, correction: float = 0.2, sides: bool = True, exact_sides: bool = True
) -> Samples:
    """Flatten a log into samples: centre images, then left and right images.

    A side image's label is the row's exact side label (``steering_left``/``steering_right``)
    where the row has one and ``exact_sides`` is set, else the centre label ``+ correction``
    (left) or ``− correction`` (right), the Udacity recipe.

    Args:
        log: the dataset.
        correction: steering added for the left camera and subtracted for the right one, where
            there is no exact label.
        sides: include the left/right images.
        exact_sides: use the exact side labels where present (False: the fixed correction
            everywhere, the thesis's recipe).

    Returns:
        The samples (steering clipped to [-1, 1]), with the camera of each.
    """
    n = len(log)
    paths = list(log.center)
    steer = [log.steering]
    thr = [log.throttle]
    spd = [log.speed]
    cams = [np.full(n, CAMERA_CENTRE, dtype=np.int8)]
    ts = log.target_speed
    if sides:

        def side(
            exact: NDArray[np.float64] | None, fixed: NDArray[np.float64]
        ) -> NDArray[np.float64]:
            if exact is None or not exact_sides:
                return fixed
            return np.asarray(np.where(np.isnan(exact), fixed, exact), dtype=float)

        paths += list(log.left) + list(log.right)
        steer += [
            side(log.steering_left, log.steering + correction),
            side(log.steering_right, log.steering - correction),
        ]
        thr += [log.throttle, log.throttle]
        spd += [log.speed, log.speed]
        cams += [np.full(n, CAMERA_LEFT, dtype=np.int8), np.full(n, CAMERA_RIGHT, dtype=np.int8)]
    return Samples(
        paths,
        np.clip(np.concatenate(steer), -1.0, 1.0),
        np.concatenate(thr),
        np.concatenate(spd),
        None if ts is None else np.concatenate([ts, ts, ts] if sides else [ts]),
        np.concatenate(cams),
    )


def steering_histogram(
    steering: NDArray[np.float64], *, n_bins: int = 25, lo: float = -1.0, hi: float = 1.0
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Histogram of steering values (Fig. 6.4): ``(counts, edges)`` over [lo, hi]."""
    edges = np.linspace(lo, hi, n_bins + 1)
    counts = np.bincount(_bin_index(steering, edges), minlength=n_bins)
    return counts.astype(np.int64), edges


def _bin_index(steering: NDArray[np.float64], edges: NDArray[np.float64]) -> NDArray[np.int64]:
    """Bin of each value: [e_k, e_k+1), the last bin closed; values outside are clipped in."""
    s = np.clip(np.asarray(steering, dtype=float), edges[0], edges[-1])
    return np.clip(np.searchsorted(edges, s, side="right") - 1, 0, len(edges) - 2).astype(np.int64)


def balance_indices(
    steering: NDArray[np.float64],
    rng: np.random.Generator,
    *,
    n_bins: int = 25,
    max_per_bin: int = 200,
    lo: float = -1.0,
    hi: float = 1.0,
) -> NDArray[np.int64]:
    """Indices kept by the thesis's balancing (Fig. 6.5): at most ``max_per_bin`` per bin.

    Args:
        steering: steering labels.
        rng: random generator (which samples of a full bin are kept).
        n_bins: histogram bins over [lo, hi].
        max_per_bin: threshold (thesis: 200).
        lo: lowest steering.
        hi: highest steering.

    Returns:
        Sorted indices of the kept samples.
    """
    b = _bin_index(steering, np.linspace(lo, hi, n_bins + 1))
    keep: list[NDArray[np.int64]] = []
    for k in range(n_bins):
        idx = np.flatnonzero(b == k)
        if len(idx) > max_per_bin:
            idx = np.sort(rng.choice(idx, size=max_per_bin, replace=False))
        keep.append(idx)
    return np.sort(np.concatenate(keep)).astype(np.int64)


def split_indices(
    n: int, rng: np.random.Generator, *, val_fraction: float = 0.2
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Random training/validation split (thesis: 8:2, Fig. 6.6): ``(train, val)`` indices."""
    if not 0.0 < val_fraction < 1.0:
        raise ValueError(f"val_fraction: {val_fraction} (must be in (0, 1))")
    perm = rng.permutation(n)
    n_val = round(n * val_fraction)
    return np.sort(perm[n_val:]).astype(np.int64), np.sort(perm[:n_val]).astype(np.int64)


def load_images(paths: Sequence[Path], *, size: tuple[int, int] = (66, 200)) -> NDArray[np.uint8]:
    """Load images as ``(N, H, W, 3)`` uint8, resized to ``size`` = (H, W) where they differ.

    A Udacity 160×320 frame is first cropped as NVIDIA/Udacity pipelines do (top 60 rows of sky
    and bottom 25 rows of bonnet removed) and then resized; our 66×200 renders are used as is.
    """
    from PIL import Image

    h, w = size
    out = np.empty((len(paths), h, w, 3), dtype=np.uint8)
    for k, p in enumerate(paths):
        try:
            with Image.open(p) as im:
                if im.width * im.height > MAX_IMAGE_PIXELS:
                    raise DatasetError(
                        f"{p}: {im.width}x{im.height} image is above the limit of "
                        f"{MAX_IMAGE_PIXELS} pixels (uvnav.driving.dataset.MAX_IMAGE_PIXELS)"
                    )
                img = im.convert("RGB")
                if img.size == (320, 160) and (h, w) != (160, 320):
                    img = img.crop((0, 60, 320, 135))
                if img.size != (w, h):
                    img = img.resize((w, h), Image.Resampling.BILINEAR)
                out[k] = np.asarray(img)
        except (OSError, ValueError, Image.DecompressionBombError) as exc:
            if isinstance(exc, DatasetError):
                raise
            raise DatasetError(f"{p}: not a readable image ({exc})") from None
    return out
