"""Layer 2: estimators a controller or the sensing pipeline may own (no torch at import time)."""

from uvnav.prediction.finite_difference import FiniteDifferenceEstimator

__all__ = ["FiniteDifferenceEstimator"]
