"""The standard prognostics metrics (Saxena et al., "Metrics for offline evaluation of
prognostic performance", IJPHM 2010) on one life's RUL predictions.

``days [P]`` the prediction times, ``predicted [P]`` the estimates and ``eol`` the true failure
day; ``start`` the first day predictions are judged from (the degradation's onset), so that
``lambda`` fractions are of the stretch from the onset to the failure.
"""

from __future__ import annotations

import math

import numpy as np


def _at_lambda(days: np.ndarray, start: float, eol: float, lam: float) -> int | None:
    """Position of the first prediction at or after ``start + lam * (eol - start)``."""
    t = start + lam * (eol - start)
    later = np.flatnonzero(np.asarray(days, float) >= t - 1e-9)
    return int(later[0]) if len(later) else None


def alpha_lambda(
    days: np.ndarray, predicted: np.ndarray, eol: float, start: float, alpha: float, lam: float
) -> bool | None:
    """Is the prediction at ``lambda`` within ``(1 +- alpha)`` of the true RUL? (None: no
    prediction that late)."""
    k = _at_lambda(days, start, eol, lam)
    if k is None:
        return None
    truth = eol - days[k]
    return bool(abs(predicted[k] - truth) <= alpha * truth)


def relative_accuracy(
    days: np.ndarray, predicted: np.ndarray, eol: float, start: float, lam: float = 0.5
) -> float | None:
    """``1 - |RUL* - RUL| / RUL*`` at ``lambda`` (0.5: half-life); can be negative."""
    k = _at_lambda(days, start, eol, lam)
    if k is None:
        return None
    truth = eol - days[k]
    if not math.isfinite(predicted[k]):
        return -math.inf
    return float(1.0 - abs(truth - predicted[k]) / truth)


def prognostic_horizon(
    days: np.ndarray, predicted: np.ndarray, eol: float, start: float, alpha: float
) -> float:
    """``eol - t_i`` for the first prediction time ``t_i`` (at or after ``start``) from which
    every prediction lies within ``alpha * (eol - start)`` of the true RUL; 0 when none does."""
    days, predicted = np.asarray(days, float), np.asarray(predicted, float)
    inside = np.abs(predicted - (eol - days)) <= alpha * (eol - start)
    inside &= days >= start
    horizon = 0.0
    for k in range(len(days) - 1, -1, -1):  # the longest run of hits that reaches the end
        if not inside[k]:
            break
        horizon = float(eol - days[k])
    return horizon
