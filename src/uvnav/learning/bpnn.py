"""Back-propagation neural network that locates the point to evade (thesis Chapter 5, §5.3-5.4).

Reference: Y. Zhang and J. Zhang, "An Obstacle Avoidance Method for Sonar-based Robots Avoiding
Shape Changeable Obstacles in Underwater Environments", ICCAE 2022; thesis Chapter 5: Fig. 5.1
(input layer X, one hidden layer, output layer Y, weights W and V), Fig. 5.4 (nine inputs — the
sonar readings after the adaptive coefficient, eq. (5.8) — and two outputs: the minimum robot-
obstacle distance and the number of the sensor that achieves it), §5.4 (Matlab Neural Network
Toolbox: data "divided randomly to three groups, training group, validation group and testing
group"; training stops "as the network generalization no longer improves").

What is reproduced from the toolbox's defaults (``fitnet``): one hidden layer of 10 tanh
("tansig") neurons and a linear output layer; inputs and targets scaled to [-1, 1] by the
training set's min/max ("mapminmax"); a random 70/15/15 division ("dividerand": validation and
test sizes rounded half away from zero, as MATLAB's ``round``, so 150 samples give 104/23/23
and 50 give 34/8/8; :func:`split_sizes`); early stopping
after 6 consecutive validation failures ("max_fail"), returning the weights of the best
validation epoch; errors reported as target - output on each group.  The toolbox trains with
Levenberg-Marquardt; here the default is full-batch L-BFGS with a strong-Wolfe line search
(``torch.optim.LBFGS``) — the closest second-order method torch ships, for the same small-data
regime — and Adam is an option.  Weights are initialised from the caller's
``numpy.random.Generator`` (Glorot-uniform), so the same seed gives the same network.

Checkpoints are the one format of :mod:`uvnav.learning.checkpoint` (also the CNN's): a
``.safetensors`` file of the weights and normalisation arrays with a JSON header (the
configuration and the training history) in its metadata, plus a ``.json`` copy of the header;
loading parses data only and can never execute code (a pickle is refused with
:class:`CheckpointError`), and older ``uvnav-bpnn-v1`` checkpoints still load.  The forward pass
of a trained model is plain numpy (:meth:`TrainedBPNN.predict`), so the navigation law can use
it without torch.

torch is imported inside the functions that need it (extra ``learning``), with at most 2 threads.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.learning.checkpoint import CheckpointError, first_non_finite
from uvnav.learning.runtime import require_torch
from uvnav.sensors.sonar_dataset import TARGET_KINDS

#: the thesis's reported test-error ranges (target - output), Ch. 5 §5.4
THESIS_ERROR_RANGES: dict[int, dict[str, tuple[float, float]]] = {
    50: {"distance": (-1.688, 1.861), "index": (-2.806, 4.454)},
    150: {"distance": (-0.04884, 0.3578), "index": (-0.08559, 0.1147)},
}
#: what the thesis concludes from each of those ranges (§5.4): with 50 samples "the results are
#: not satisfactory as they are too scattered" (a failure it blames on too few samples); with 150
#: "the results are acceptable"
THESIS_ACCEPTED: dict[int, bool] = {50: False, 150: True}
#: the sample count whose error ranges the thesis accepts: its ranges are the bar of success
ACCEPTED_SAMPLES = 150
#: the network variants of the reproduction (:attr:`BPNNConfig.variant`, :func:`variant_config`)
VARIANTS: tuple[str, ...] = ("plain", "residual", "residual-huber")
#: Huber threshold of the robust residual variant, in scaled output units (2 % of the largest
#: training correction; chosen on seeds 0-4 and confirmed on 20 other 150-sample sets,
#: docs/thesis-notes.md)
HUBER_DELTA = 0.02
MAX_THREADS = 2


#: most neurons of one hidden layer (the thesis uses 10; a typo like 100000000 would allocate
#: gigabytes): a module constant, raise it before building a larger network
MAX_HIDDEN = 10_000


class NonFiniteError(ValueError):
    """A NaN or ±inf where a finite number is meant: in the data, the loss or the weights."""


def _model_arrays(model: TrainedBPNN) -> dict[str, Any]:
    """A trained network's arrays by checkpoint name (weights and min/max scaling)."""
    arrays: dict[str, Any] = {
        "x_lo": model.x_lo,
        "x_hi": model.x_hi,
        "y_lo": model.y_lo,
        "y_hi": model.y_hi,
    }
    for k, (w, b) in enumerate(model.weights):
        arrays[f"layer{k}.weight"] = w
        arrays[f"layer{k}.bias"] = b
    return arrays


@dataclass(frozen=True)
class BPNNConfig:
    """Network and training settings.

    Attributes:
        hidden: neurons per hidden layer (thesis Fig. 5.1: one hidden layer; toolbox default 10).
        optimizer: ``"lbfgs"`` (default, small data) or ``"adam"``.
        fractions: train/validation/test fractions of the random division (toolbox 0.7/0.15/0.15).
        max_epochs: largest number of epochs (``lbfgs_iterations`` L-BFGS iterations or one
            full-batch Adam step each).
        max_fail: consecutive validation failures that stop training (toolbox 6).
        learning_rate: Adam step size (L-BFGS uses 1 with a line search).
        weight_decay: L2 penalty on the weights (0: none, as the toolbox).
        residual: learn the correction to a per-sample ``offset`` (the min/argmin of the raw
            readings) instead of the outputs themselves; the output layer starts at zero, so the
            untrained network *is* the baseline (not in the thesis; off by default).
        lbfgs_iterations: L-BFGS iterations per epoch (validation is checked once per epoch; one
            toolbox Levenberg-Marquardt epoch moves about as far as several L-BFGS iterations).
        huber_delta: ``> 0``: a robust loss, Huber's (P. J. Huber, 1964) with this threshold in
            scaled output units, for training and for the validation stop; ``0``: the mean
            squared error of the toolbox (default).  Not in the thesis: about 2 % of the
            sensor-index labels are beam ties whose corrections of 1-8 are not in the readings
            (docs/thesis-notes.md); a squared loss lets those few pull every other prediction.
    """

    hidden: tuple[int, ...] = (10,)
    optimizer: str = "lbfgs"
    fractions: tuple[float, float, float] = (0.7, 0.15, 0.15)
    max_epochs: int = 1000
    max_fail: int = 6
    learning_rate: float = 1e-2
    weight_decay: float = 0.0
    residual: bool = False
    lbfgs_iterations: int = 10
    huber_delta: float = 0.0

    def __post_init__(self) -> None:
        if self.optimizer not in ("lbfgs", "adam"):
            raise ValueError(f"optimizer must be 'lbfgs' or 'adam' (got {self.optimizer!r})")
        if not self.hidden or any(
            isinstance(h, bool) or int(h) != h or not 1 <= int(h) <= MAX_HIDDEN for h in self.hidden
        ):
            raise ValueError(
                f"hidden must list layer sizes in 1..{MAX_HIDDEN} (got {self.hidden!r}; "
                "uvnav.learning.bpnn.MAX_HIDDEN)"
            )
        f = self.fractions
        if len(f) != 3 or any(x < 0 for x in f) or abs(sum(f) - 1.0) > 1e-9 or f[0] <= 0:
            raise ValueError(f"fractions must be three numbers >= 0 summing to 1 (got {f!r})")
        if self.max_epochs < 1 or self.max_fail < 1:
            raise ValueError("max_epochs and max_fail must be >= 1")
        if not self.huber_delta >= 0:
            raise ValueError(f"huber_delta must be >= 0 (got {self.huber_delta!r})")

    @property
    def variant(self) -> str:
        """``"plain"``, ``"residual"`` or ``"residual-huber"`` (names of results and figures)."""
        if not self.residual:
            return "plain" if self.huber_delta == 0 else "plain-huber"
        return "residual" if self.huber_delta == 0 else "residual-huber"


def variant_config(variant: str, **settings: Any) -> BPNNConfig:
    """The configuration of a named variant (:data:`VARIANTS`): ``plain`` (the thesis's network),
    ``residual`` (learns the correction to min/argmin of the raw readings) or ``residual-huber``
    (the same with Huber's loss, threshold :data:`HUBER_DELTA`); ``settings`` override the rest.

    Raises:
        ValueError: an unknown variant or setting value.
    """
    if variant not in VARIANTS:
        raise ValueError(f"variant: {variant!r} (must be one of {', '.join(VARIANTS)})")
    residual = variant != "plain"
    huber = HUBER_DELTA if variant == "residual-huber" else 0.0
    return BPNNConfig(residual=residual, huber_delta=huber, **settings)


def _round_half_away(x: float) -> int:
    """MATLAB's ``round`` (halves away from zero; Python's ``round`` goes to the even one)."""
    return math.floor(abs(x) + 0.5) * (1 if x >= 0 else -1)


def split_sizes(n: int, fractions: tuple[float, float, float]) -> tuple[int, int, int]:
    """Sizes of the train/validation/test division of ``n`` samples, as the toolbox's
    ``dividerand`` computes them: validation and test ``round(fraction * n)`` with MATLAB's
    rounding (at least one each when its fraction > 0), training the rest.

    Raises:
        ValueError: no sample left for training.
    """
    total = sum(fractions)
    n_val = max(1, _round_half_away(fractions[1] / total * n)) if fractions[1] > 0 else 0
    n_test = max(1, _round_half_away(fractions[2] / total * n)) if fractions[2] > 0 else 0
    n_train = n - n_val - n_test
    if n_train < 1:
        raise ValueError(f"too few samples ({n}) for the division {fractions}")
    return n_train, n_val, n_test


def split_indices(
    n: int, rng: np.random.Generator, fractions: tuple[float, float, float]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random train/validation/test division of ``range(n)`` (toolbox ``dividerand``; sizes
    :func:`split_sizes`)."""
    n_train, n_val, _ = split_sizes(n, fractions)
    perm = rng.permutation(n)
    return perm[:n_train], perm[n_train : n_train + n_val], perm[n_train + n_val :]


def _minmax(x: FloatArray) -> tuple[FloatArray, FloatArray]:
    lo, hi = x.min(axis=0), x.max(axis=0)
    hi = np.where(hi - lo < 1e-12, lo + 1.0, hi)
    return lo, hi


def _scale(x: FloatArray, lo: FloatArray, hi: FloatArray) -> FloatArray:
    return np.asarray(2.0 * (x - lo) / (hi - lo) - 1.0)


def _unscale(y: FloatArray, lo: FloatArray, hi: FloatArray) -> FloatArray:
    return np.asarray((y + 1.0) * 0.5 * (hi - lo) + lo)


@dataclass
class TrainedBPNN:
    """A trained network: weights, normalisation, and what happened during training.

    Attributes:
        config: the settings it was trained with.
        weights: per layer, ``(W (out, in), b (out,))``.
        x_lo, x_hi, y_lo, y_hi: min/max scaling of inputs and outputs (training set).
        history: ``{"train": [...], "val": [...]}`` mean squared error (scaled units) per epoch.
        best_epoch: epoch whose weights were kept (lowest validation error).
        stop_reason: why training stopped.
        split: ``{"train": idx, "val": idx, "test": idx}`` of the division (may be empty).
        target_kind: what the outputs were trained to be: ``"geometry"`` (true nearest distance
            and sensor) or ``"readings"`` (min/argmin of the inputs, the thesis's targets);
            :data:`uvnav.sensors.sonar_dataset.TARGET_KINDS`.
    """

    config: BPNNConfig
    weights: list[tuple[FloatArray, FloatArray]]
    x_lo: FloatArray
    x_hi: FloatArray
    y_lo: FloatArray
    y_hi: FloatArray
    history: dict[str, list[float]] = field(default_factory=lambda: {"train": [], "val": []})
    best_epoch: int = 0
    stop_reason: str = ""
    split: dict[str, np.ndarray] = field(default_factory=dict)
    target_kind: str = "geometry"

    @property
    def variant(self) -> str:
        """The network variant (:attr:`BPNNConfig.variant`)."""
        return self.config.variant

    @property
    def n_inputs(self) -> int:
        return int(self.weights[0][0].shape[1])

    def predict(self, inputs: FloatArray, offset: FloatArray | None = None) -> FloatArray:
        """Outputs (n, 2) — distance [m], sensor index — for inputs (n, 9) or (9,) (numpy only).

        Raises:
            ValueError: wrong input width, or a residual network without its ``offset`` (n, 2).
        """
        x = np.atleast_2d(np.asarray(inputs, dtype=float))
        if x.shape[1] != self.n_inputs:
            raise ValueError(f"expected {self.n_inputs} inputs per sample, got {x.shape[1]}")
        h = _scale(x, self.x_lo, self.x_hi)
        for k, (w, b) in enumerate(self.weights):
            h = h @ w.T + b
            if k < len(self.weights) - 1:
                h = np.tanh(h)
        out = _unscale(h, self.y_lo, self.y_hi)
        if self.config.residual:
            if offset is None:
                raise ValueError("a residual network needs the offset (min/argmin of readings)")
            out = out + np.atleast_2d(np.asarray(offset, dtype=float))
        return out


def _init_weights(
    sizes: list[int], rng: np.random.Generator
) -> list[tuple[FloatArray, FloatArray]]:
    out = []
    for fan_in, fan_out in itertools.pairwise(sizes):
        lim = math.sqrt(6.0 / (fan_in + fan_out))
        out.append((rng.uniform(-lim, lim, (fan_out, fan_in)), np.zeros(fan_out)))
    return out


def train_bpnn(
    inputs: FloatArray,
    targets: FloatArray,
    rng: np.random.Generator,
    config: BPNNConfig | None = None,
    *,
    split: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    offset: FloatArray | None = None,
    target_kind: str = "geometry",
) -> TrainedBPNN:
    """Train the BPNN on ``inputs`` (n, 9) and ``targets`` (n, 2) with early stopping.

    Args:
        inputs: adapted sonar readings [m].
        targets: true distance [m] and sensor index.
        rng: generator of the division and the initial weights.
        config: settings (defaults: the toolbox's ``fitnet`` shape, L-BFGS).
        split: an explicit ``(train, val, test)`` division instead of a random one.
        offset: (n, 2) per-sample baseline for ``config.residual`` (required then).
        target_kind: what ``targets`` are (recorded with the network, :class:`TrainedBPNN`).

    Returns:
        The network with the weights of its best validation epoch (the last epoch when there is
        no validation group).

    Raises:
        NonFiniteError: a NaN/±inf in ``inputs``, ``targets`` or ``offset``, or a training loss
            or weight that stops being finite (training diverged): no network is returned.
        ValueError: inconsistent shapes, or an unknown ``target_kind``.
    """
    cfg = config or BPNNConfig()
    if target_kind not in TARGET_KINDS:
        raise ValueError(f"target_kind: {target_kind!r} (one of {', '.join(TARGET_KINDS)})")
    torch = require_torch(MAX_THREADS)
    x = np.asarray(inputs, dtype=float)
    y = np.asarray(targets, dtype=float)
    if x.ndim != 2 or y.ndim != 2 or len(x) != len(y):
        raise ValueError(f"inputs (n, k) and targets (n, m) must match (got {x.shape}, {y.shape})")
    given = {"inputs": x, "targets": y, **({"offset": offset} if offset is not None else {})}
    bad = first_non_finite(given)
    if bad is not None:
        raise NonFiniteError(f"training data: {bad} is not a finite number")
    if cfg.residual:
        if offset is None:
            raise ValueError("residual training needs the per-sample offset (n, 2)")
        y = y - np.asarray(offset, dtype=float)
    tr, va, te = split if split is not None else split_indices(len(x), rng, cfg.fractions)
    x_lo, x_hi = _minmax(x[tr])
    y_lo, y_hi = _minmax(y[tr])
    xs = torch.as_tensor(_scale(x, x_lo, x_hi), dtype=torch.float64)
    ys = torch.as_tensor(_scale(y, y_lo, y_hi), dtype=torch.float64)
    sizes = [x.shape[1], *[int(h) for h in cfg.hidden], y.shape[1]]
    layers: list[Any] = []
    init = _init_weights(sizes, rng)
    if cfg.residual:
        init[-1] = (np.zeros_like(init[-1][0]), np.zeros_like(init[-1][1]))
        y_lo, y_hi = -np.abs(y[tr]).max(axis=0) - 1e-6, np.abs(y[tr]).max(axis=0) + 1e-6
        ys = torch.as_tensor(_scale(y, y_lo, y_hi), dtype=torch.float64)
    for k, (w, b) in enumerate(init):
        lin = torch.nn.Linear(w.shape[1], w.shape[0]).double()
        with torch.no_grad():
            lin.weight.copy_(torch.as_tensor(w))
            lin.bias.copy_(torch.as_tensor(b))
        layers.append(lin)
        if k < len(sizes) - 2:
            layers.append(torch.nn.Tanh())
    net = torch.nn.Sequential(*layers)
    tr_t, va_t = torch.as_tensor(tr), torch.as_tensor(va)
    if cfg.optimizer == "lbfgs":
        opt = torch.optim.LBFGS(
            net.parameters(),
            lr=1.0,
            max_iter=cfg.lbfgs_iterations,
            history_size=50,
            line_search_fn="strong_wolfe",
        )
    else:
        opt = torch.optim.Adam(net.parameters(), lr=cfg.learning_rate)

    def loss_on(idx: Any) -> Any:
        err = net(xs[idx]) - ys[idx]
        if cfg.huber_delta > 0:  # scaled so that small errors weigh as in the squared loss
            loss = (
                torch.nn.functional.huber_loss(err, torch.zeros_like(err), delta=cfg.huber_delta)
                * 2.0
            )
        else:
            loss = (err * err).mean()
        if cfg.weight_decay > 0:
            loss = loss + cfg.weight_decay * sum((p * p).sum() for p in net.parameters())
        return loss

    def closure() -> Any:
        opt.zero_grad()
        loss = loss_on(tr_t)
        loss.backward()
        return loss

    history: dict[str, list[float]] = {"train": [], "val": []}
    best_state = [p.detach().clone() for p in net.parameters()]
    best_val, best_epoch, fails = math.inf, 0, 0
    stop = "max_epochs"
    for epoch in range(1, cfg.max_epochs + 1):
        opt.step(closure)
        with torch.no_grad():
            tl = float(loss_on(tr_t))
            vl = float(loss_on(va_t)) if len(va) else tl
        history["train"].append(tl)
        history["val"].append(vl)
        if not (math.isfinite(tl) and math.isfinite(vl)):
            which = "training" if not math.isfinite(tl) else "validation"
            raise NonFiniteError(
                f"training diverged at epoch {epoch}: the {which} loss is "
                f"{tl if which == 'training' else vl} (try --optimizer lbfgs or a smaller "
                "learning rate); no model was kept"
            )
        if vl < best_val:
            best_val, best_epoch, fails = vl, epoch, 0
            best_state = [p.detach().clone() for p in net.parameters()]
        else:
            fails += 1
            if len(va) and fails >= cfg.max_fail:
                stop = "validation_stop"
                break
        if tl < 1e-12:
            stop = "min_error"
            break
    params = [p.numpy().copy() for p in best_state]
    weights = [(params[2 * i], params[2 * i + 1]) for i in range(len(params) // 2)]
    model = TrainedBPNN(
        config=cfg,
        weights=weights,
        x_lo=x_lo,
        x_hi=x_hi,
        y_lo=y_lo,
        y_hi=y_hi,
        history=history,
        best_epoch=best_epoch,
        stop_reason=stop,
        split={"train": np.asarray(tr), "val": np.asarray(va), "test": np.asarray(te)},
        target_kind=target_kind,
    )
    bad = first_non_finite(_model_arrays(model))
    if bad is not None:
        raise NonFiniteError(f"training produced a non-finite network: {bad}")
    return model


@dataclass(frozen=True)
class ErrorSummary:
    """Errors target - output of one output on one group.

    Attributes:
        lo, hi: error range (min, max).
        mae: mean |error|.
        rmse: root mean square error.
        n: number of samples.
    """

    lo: float
    hi: float
    mae: float
    rmse: float
    n: int

    @staticmethod
    def of(errors: FloatArray) -> ErrorSummary:
        e = np.asarray(errors, dtype=float)
        if e.size == 0:
            return ErrorSummary(math.nan, math.nan, math.nan, math.nan, 0)
        return ErrorSummary(
            float(e.min()),
            float(e.max()),
            float(np.abs(e).mean()),
            float(np.sqrt((e * e).mean())),
            int(e.size),
        )


def error_table(
    predicted: FloatArray, targets: FloatArray, baseline: FloatArray | None = None
) -> dict[str, dict[str, Any]]:
    """Error summaries (target - output) for distance and index, the network's and the baseline's,
    plus the rate at which the rounded index is exactly right."""
    p, t = np.atleast_2d(predicted), np.atleast_2d(targets)
    out: dict[str, dict[str, Any]] = {}
    for name, pred in (("network", p), ("baseline", baseline)):
        if pred is None:
            continue
        pr = np.atleast_2d(pred)
        out[name] = {
            "distance": asdict(ErrorSummary.of(t[:, 0] - pr[:, 0])),
            "index": asdict(ErrorSummary.of(t[:, 1] - pr[:, 1])),
            "index_accuracy": float(np.mean(np.clip(np.rint(pr[:, 1]), 1, 9) == t[:, 1]))
            if len(pr)
            else math.nan,
        }
    return out


# ------------------------------------------------------------------------------------ checkpoints


def save_checkpoint(model: TrainedBPNN, path: Path) -> tuple[Path, Path]:
    """Write ``<path>.safetensors`` (weights and min/max scaling as float64 arrays, the header in
    its metadata) and ``<path>.json`` (the header's copy), in the one checkpoint format of
    :mod:`uvnav.learning.checkpoint` (kind ``bpnn``; the record holds the history, best epoch,
    stop reason, division and the kind of targets).

    Returns:
        The two paths written.

    Raises:
        NonFiniteError: a weight or scaling value is NaN/±inf (nothing is written).
    """
    from uvnav.learning.checkpoint import write_checkpoint

    arrays = {k: np.asarray(v, dtype=np.float64) for k, v in _model_arrays(model).items()}
    bad = first_non_finite(arrays)
    if bad is not None:
        raise NonFiniteError(f"{path}: refusing to save a network with {bad}")
    base = Path(path)
    if base.suffix in (".safetensors", ".json"):
        base = base.with_suffix("")
    record = {
        "history": model.history,
        "best_epoch": model.best_epoch,
        "stop_reason": model.stop_reason,
        "split": {k: [int(i) for i in v] for k, v in model.split.items()},
        "target_kind": model.target_kind,
    }
    st_path = write_checkpoint(
        base.with_suffix(".safetensors"),
        arrays,
        kind="bpnn",
        config=asdict(model.config),
        record=record,
    )
    return st_path, st_path.with_suffix(".json")


def network_locator(model: str) -> Any:
    """The ``network`` locator of ``zhang2022-uuv3d-v1`` (its entry point in the
    ``uvnav.locators`` group): a :class:`~uvnav.controllers.zhang_uuv3d.ModelLocator` of the BPNN
    in the checkpoint ``model`` (either file's path, or the stem).

    Raises:
        ValueError: no checkpoint named; CheckpointError: it cannot be read (one line).
    """
    from uvnav.controllers.zhang_uuv3d import ModelLocator

    if not model:
        raise ValueError(
            "no checkpoint given (the network locator reads a BPNN checkpoint: model=PATH)"
        )
    return ModelLocator(load_checkpoint(Path(model)))


def load_checkpoint(path: Path) -> TrainedBPNN:
    """Read a BPNN checkpoint (either file's path, or the stem): the one format of
    :mod:`uvnav.learning.checkpoint`, or a legacy ``uvnav-bpnn-v1`` one (its reader is there).

    Only data are parsed (safetensors header + raw arrays, and JSON); nothing is unpickled, and
    torch is not needed.

    Raises:
        CheckpointError: missing file, a file that is not safetensors (e.g. a pickle), another
            format or kind, missing/inconsistent arrays, or a weight or scaling value that is
            NaN/±inf — one line naming the file and the problem.
    """
    from uvnav.learning.checkpoint import read_checkpoint, weights_path

    st_path = weights_path(path)
    if not st_path.is_file():
        raise CheckpointError(f"{st_path}: checkpoint file not found")
    try:
        tensors, header = read_checkpoint(st_path, "bpnn")
    except FileNotFoundError as exc:  # the legacy JSON vanished meanwhile
        raise CheckpointError(f"{exc.filename}: checkpoint file not found") from None
    record = dict(header.get("record") or {})
    try:
        cfg_d = dict(header["config"])
        for key in ("hidden", "fractions"):
            value = cfg_d.get(key)
            if not isinstance(value, list | tuple) or any(isinstance(v, bool | str) for v in value):
                raise ValueError(f"{key}: must be a list of numbers (got {value!r:.40})")
            cfg_d[key] = tuple(value)
        cfg = BPNNConfig(**cfg_d)
    except (TypeError, ValueError) as exc:
        raise CheckpointError(f"{st_path}: config: {exc}") from None
    try:
        n_layers = len(cfg.hidden) + 1
        weights = [
            (tensors[f"layer{k}.weight"], tensors[f"layer{k}.bias"]) for k in range(n_layers)
        ]
        scal = {k: tensors[k] for k in ("x_lo", "x_hi", "y_lo", "y_hi")}
    except (KeyError, TypeError, ValueError) as exc:
        raise CheckpointError(f"{st_path}: incomplete checkpoint ({exc})") from exc
    for k in range(1, n_layers):
        if weights[k][0].shape[1] != weights[k - 1][0].shape[0]:
            raise CheckpointError(f"{st_path}: layer{k}.weight does not fit layer{k - 1}")
    target_kind = record.get("target_kind", "geometry")  # older checkpoints: true geometry
    if target_kind not in TARGET_KINDS:
        raise CheckpointError(
            f"{st_path}: record.target_kind {target_kind!r:.40} (one of {', '.join(TARGET_KINDS)})"
        )
    sizes = [int(w.shape[0]) for w, _ in weights[:-1]]
    if sizes != [int(h) for h in cfg.hidden]:
        raise CheckpointError(
            f"{st_path}: config.hidden {list(cfg.hidden)} does not match the weights' hidden "
            f"layer sizes {sizes}"
        )
    return TrainedBPNN(
        config=cfg,
        weights=weights,
        history=dict(record.get("history", {})),
        best_epoch=int(record.get("best_epoch", 0)),
        stop_reason=str(record.get("stop_reason", "")),
        split={k: np.asarray(v, dtype=np.int64) for k, v in dict(record.get("split", {})).items()},
        target_kind=target_kind,
        **scal,
    )
