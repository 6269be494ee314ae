"""Auto-regressive prediction of obstacle motion, thesis Chapter 3 §3.3.1, eqs. (3.13)-(3.14).

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW, Chapter 3 (ICCAR 2020); G. E. P. Box, G. M. Jenkins, *Time Series Analysis*; the
fits are statsmodels' ``ar_select_order`` / ``AutoReg`` (OLS, as the thesis asks), the whiteness
check statsmodels' ``acorr_ljungbox``.

    X_t = c + sum_{i=1..p} phi_i X_{t-i} + eps_t                                      (3.13)

Per obstacle the velocity v_i and the rotation vector u_i get *independent* models (the thesis's
"two independent models"), and within each vector every component is its own univariate AR series
(the thesis writes (3.14) for the vector with scalar coefficients a_j; component-wise models
contain that case and let the order differ between components).  Samples are taken every
``period`` T_s (1 s in the thesis).

How the thesis was read (docs/thesis-notes.md):

* "We determine the order p ... using OLS": the order is chosen by an information criterion over
  OLS fits of orders 0..``max_lag`` (``ic``, BIC by default), then the chosen model is fitted by
  OLS.
* "an inspection of whether the model is reasonable": Ljung–Box test of the residuals' whiteness
  at ``lb_lags`` lags; a model whose residuals are not white (p < ``alpha``) is rejected.
* While the history is shorter than ``min_samples``, when the fit fails or is rejected, or when
  the series is constant, the prediction falls back to *constant velocity* (the last sample).
* The order is re-selected every ``reselect_every`` new samples (statsmodels, the costly part)
  and the coefficients re-estimated by OLS at that order every ``refit_every`` samples
  (:func:`refit_ols`, the same estimates as ``AutoReg``; tested against it).

k-step predictions iterate (3.13); their error std is sigma * sqrt(sum_{j<k} psi_j^2) with psi the
MA(inf) weights of the fitted model (for the fallback: the std of the sample-to-sample changes
times sqrt(k), a random walk).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from uvnav.geometry.angles import FloatArray

Criterion = Literal["aic", "bic", "hqic"]


@dataclass(frozen=True)
class ARFit:
    """A fitted univariate AR model.

    Attributes:
        order: p (0 means a constant mean).
        const: c.
        phi: (p,) coefficients phi_1..phi_p.
        sigma: residual std.
        whiteness_p: Ljung–Box p-value of the residuals (nan when not testable).
        accepted: the model passed the whiteness check.
    """

    order: int
    const: float
    phi: FloatArray
    sigma: float
    whiteness_p: float
    accepted: bool


def fit_ar(
    series: FloatArray,
    *,
    max_lag: int = 4,
    ic: Criterion = "bic",
    alpha: float = 0.05,
    lb_lags: int | None = None,
) -> ARFit:
    """Order selection by ``ic`` and OLS fit of (3.13) with a constant, plus the whiteness check.

    Raises:
        ImportError: statsmodels missing (install the ``prediction`` extra).
        ValueError: a series too short for ``max_lag`` (fewer than ``max_lag + 3`` samples).
    """
    try:
        from statsmodels.stats.diagnostic import acorr_ljungbox
        from statsmodels.tsa.ar_model import AutoReg, ar_select_order
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "AR prediction needs statsmodels: pip install 'uvnav[prediction]'"
        ) from exc
    y = np.asarray(series, dtype=float)
    if len(y) < max_lag + 3:
        raise ValueError(f"series of {len(y)} samples is too short for max_lag={max_lag}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sel = ar_select_order(y, maxlag=max_lag, ic=ic, trend="c")
        lags = sel.ar_lags
        order = int(max(lags)) if lags else 0
        res = AutoReg(y, lags=order, trend="c").fit()
    params = np.asarray(res.params, dtype=float)
    const = float(params[0])
    phi = params[1 : 1 + order].copy()
    resid = np.asarray(res.resid, dtype=float)
    sigma = float(np.sqrt(max(float(res.sigma2), 0.0)))
    n_lb = lb_lags if lb_lags is not None else max(1, min(10, len(resid) // 5))
    p_value = float("nan")
    accepted = True
    if len(resid) > n_lb + 1 and float(np.std(resid)) > 1e-12:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            lb = acorr_ljungbox(resid, lags=[n_lb], model_df=order, return_df=True)
        p_value = float(lb["lb_pvalue"].iloc[0])
        accepted = bool(not np.isfinite(p_value) or p_value >= alpha)
    return ARFit(order, const, phi, sigma, p_value, accepted)


def ljung_box_pvalue(resid: FloatArray, lags: int, model_df: int = 0) -> float:
    """Ljung–Box p-value: Q = n (n + 2) sum_{k<=h} rho_k^2 / (n - k) against chi^2(h - model_df)
    (the statistic of statsmodels' ``acorr_ljungbox``, computed directly for the refits)."""
    from scipy.stats import chi2

    r = np.asarray(resid, dtype=float)
    n = len(r)
    r = r - r.mean()
    denom = float(r @ r)
    if n <= lags + 1 or denom <= 0.0:
        return float("nan")
    rho = np.array([float(r[k:] @ r[:-k]) / denom for k in range(1, lags + 1)])
    q = n * (n + 2) * float(np.sum(rho**2 / (n - np.arange(1, lags + 1))))
    df = max(lags - model_df, 1)
    return float(chi2.sf(q, df))


def refit_ols(series: FloatArray, order: int, *, alpha: float = 0.05) -> ARFit:
    """OLS fit of (3.13) with a constant at a *given* order (the estimates of statsmodels'
    ``AutoReg(series, order, trend="c").fit()``), with the Ljung–Box check of
    :func:`ljung_box_pvalue`; used between order selections."""
    y = np.asarray(series, dtype=float)
    n = len(y)
    if n < order + 3:
        raise ValueError(f"series of {n} samples is too short for order {order}")
    cols = [np.ones(n - order)] + [y[order - i : n - i] for i in range(1, order + 1)]
    x = np.stack(cols, axis=1)
    target = y[order:]
    beta, *_ = np.linalg.lstsq(x, target, rcond=None)
    resid = target - x @ beta
    sigma = float(np.sqrt(float(resid @ resid) / len(resid)))
    n_lb = max(1, min(10, len(resid) // 5))
    p_value = ljung_box_pvalue(resid, n_lb, order) if float(np.std(resid)) > 1e-12 else float("nan")
    accepted = bool(not np.isfinite(p_value) or p_value >= alpha)
    return ARFit(order, float(beta[0]), beta[1:].copy(), sigma, p_value, accepted)


def psi_weights(phi: FloatArray, k: int) -> FloatArray:
    """First ``k`` MA(inf) weights psi_0 = 1, psi_j = sum_i phi_i psi_{j-i}."""
    psi = np.zeros(max(k, 1))
    psi[0] = 1.0
    for j in range(1, k):
        s = 0.0
        for i, ph in enumerate(phi, start=1):
            if j - i >= 0:
                s += ph * psi[j - i]
        psi[j] = s
    return psi


def ar_forecast(history: FloatArray, fit: ARFit, k: int) -> tuple[FloatArray, FloatArray]:
    """``k``-step forecasts of (3.13) from ``history`` (newest last): (means (k,), stds (k,))."""
    h = list(np.asarray(history, dtype=float)[-max(fit.order, 1) :])
    means = np.empty(k)
    for j in range(k):
        x = fit.const
        for i, ph in enumerate(fit.phi, start=1):
            x += ph * h[-i]
        means[j] = x
        h.append(x)
    psi = psi_weights(fit.phi, k)
    stds = fit.sigma * np.sqrt(np.cumsum(psi**2))
    return means, stds


@dataclass(frozen=True)
class VectorPrediction:
    """k-step prediction of a vector series.

    Attributes:
        mean: (k, d) predicted values for steps 1..k (one step = one period).
        std: (k, d) their error std.
        model: ``"ar"`` where every component used its AR fit, ``"constant"`` for the fallback,
            ``"mixed"`` otherwise.
        orders: the AR order of each component (-1 for the fallback).
    """

    mean: FloatArray
    std: FloatArray
    model: str
    orders: tuple[int, ...]


@dataclass
class ARPredictor:
    """Online AR predictor of one vector quantity (an obstacle's v_i or u_i).

    Attributes:
        dim: vector dimension.
        period: sampling period T_s [s].
        max_lag: largest order considered.
        ic: order criterion ("bic" default, "aic", "hqic").
        min_samples: samples needed before AR is tried (constant-velocity fallback before).
        window: newest samples used for fitting.
        refit_every: refit the coefficients (OLS at the current orders) after this many new
            samples.
        reselect_every: re-select the orders (statsmodels ``ar_select_order``) after this many
            new samples.
        alpha: significance of the Ljung–Box whiteness check.
    """

    dim: int = 3
    period: float = 1.0
    max_lag: int = 4
    ic: Criterion = "bic"
    min_samples: int = 12
    window: int = 60
    refit_every: int = 1
    reselect_every: int = 10
    alpha: float = 0.05
    _times: list[float] = field(default_factory=list)
    _values: list[FloatArray] = field(default_factory=list)
    _fits: list[ARFit | None] = field(default_factory=list)
    _since_fit: int = 0
    _since_select: int = 0
    #: predictions by horizon k since the last kept sample (they change only with a new sample)
    _cache: dict[int, VectorPrediction] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.min_samples < self.max_lag + 3:
            raise ValueError(f"min_samples must be >= max_lag + 3 (got {self.min_samples})")
        if not (self.period > 0):
            raise ValueError(f"period must be > 0 (got {self.period!r})")

    @property
    def n_samples(self) -> int:
        return len(self._values)

    @property
    def history(self) -> FloatArray:
        """(n, dim) samples, oldest first."""
        return np.array(self._values).reshape(-1, self.dim)

    @property
    def next_sample_time(self) -> float:
        """The earliest time [s] at which :meth:`observe` keeps a measurement (-inf when empty)."""
        return self._times[-1] + self.period - 1e-9 if self._times else -math.inf

    def observe(self, t: float, value: FloatArray) -> bool:
        """Offer a measurement at time ``t`` [s]; it is kept when a period has passed since the
        last kept sample (sampling at T_s).  Returns True when kept."""
        if self._times and t < self._times[-1] + self.period - 1e-9:
            return False
        self._times.append(float(t))
        self._values.append(np.asarray(value, dtype=float).reshape(self.dim).copy())
        if len(self._values) > self.window:
            del self._values[0], self._times[0]
        self._since_fit += 1
        self._since_select += 1
        self._cache.clear()
        return True

    def _refit(self) -> None:
        y = self.history
        select = not self._fits or self._since_select >= self.reselect_every
        fits: list[ARFit | None] = []
        for j in range(self.dim):
            col = y[:, j]
            if float(np.ptp(col)) < 1e-9:
                fits.append(None)
                continue
            prev = self._fits[j] if j < len(self._fits) else None
            try:
                if select or prev is None:
                    fits.append(fit_ar(col, max_lag=self.max_lag, ic=self.ic, alpha=self.alpha))
                else:
                    fits.append(refit_ols(col, prev.order, alpha=self.alpha))
            except (ValueError, np.linalg.LinAlgError):
                fits.append(None)
        self._fits = fits
        self._since_fit = 0
        if select:
            self._since_select = 0

    def predict(self, k: int = 1) -> VectorPrediction:
        """Predictions for the next ``k`` periods (AR, or the constant-velocity fallback).

        Between two kept samples the same prediction is returned (computed once: a controller
        asks every decision, a sample arrives every T_s); do not modify its arrays."""
        hit = self._cache.get(k)
        if hit is None:
            hit = self._cache[k] = self._predict(k)
        return hit

    def _predict(self, k: int) -> VectorPrediction:
        n = self.n_samples
        if n == 0:
            return VectorPrediction(
                np.zeros((k, self.dim)), np.full((k, self.dim), np.inf), "constant",
                (-1,) * self.dim,
            )  # fmt: skip
        y = self.history
        last = y[-1]
        if n < self.min_samples:
            return self._constant(y, k)
        if not self._fits or self._since_fit >= self.refit_every:
            self._refit()
        mean = np.empty((k, self.dim))
        std = np.empty((k, self.dim))
        orders = []
        used_ar = 0
        cv = self._constant(y, k)
        for j, fit in enumerate(self._fits):
            if fit is None or not fit.accepted:
                mean[:, j] = last[j]
                std[:, j] = cv.std[:, j]
                orders.append(-1)
                continue
            m, s = ar_forecast(y[:, j], fit, k)
            mean[:, j] = m
            std[:, j] = s
            orders.append(fit.order)
            used_ar += 1
        model = "ar" if used_ar == self.dim else ("constant" if used_ar == 0 else "mixed")
        return VectorPrediction(mean, std, model, tuple(orders))

    def _constant(self, y: FloatArray, k: int) -> VectorPrediction:
        step_std = np.std(np.diff(y, axis=0), axis=0) if len(y) >= 3 else np.zeros(self.dim)
        std = step_std[None] * np.sqrt(np.arange(1, k + 1))[:, None]
        return VectorPrediction(np.repeat(y[-1][None], k, axis=0), std, "constant",
                                (-1,) * self.dim)  # fmt: skip


def one_step_errors(series: FloatArray, predictor: ARPredictor) -> tuple[FloatArray, FloatArray]:
    """Feed ``series`` (n, d), sampled once per period, through ``predictor`` and return the
    one-step prediction errors of the predictor and of constant velocity (last value), each
    (m, d), for every step after the predictor's ``min_samples`` (for comparisons)."""
    y = np.asarray(series, dtype=float).reshape(len(series), -1)
    err_ar = []
    err_cv = []
    for i in range(len(y) - 1):
        predictor.observe(i * predictor.period, y[i])
        if predictor.n_samples >= predictor.min_samples:
            pred = predictor.predict(1)
            err_ar.append(pred.mean[0] - y[i + 1])
            err_cv.append(y[i] - y[i + 1])
    return np.array(err_ar).reshape(-1, y.shape[1]), np.array(err_cv).reshape(-1, y.shape[1])


def rms(x: FloatArray) -> float:
    """Root mean square of all entries (nan for none)."""
    a = np.asarray(x, dtype=float)
    return float(math.sqrt(float(np.mean(a * a)))) if a.size else float("nan")
