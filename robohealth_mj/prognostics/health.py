"""A health index per joint and session, from the windows a model scored in that session.

Each window says how likely a mechanical fault is (class probabilities), where (joint
probabilities) and how bad (the severity head). The session's raw index of joint j is the mean
over its windows of ``P(mechanical fault) * P(joint j) * severity``: the severity the model
attributes to j per window of running. Windows in which the joint barely moves show no evidence and
pull the mean down; a monotone calibration fitted on training lives (:class:`Calibration`) maps the
raw index to the severity scale. Its interval comes from a block bootstrap over the session's
windows (neighbouring windows overlap, so whole blocks are resampled).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.numeric import softmax
from robohealth_mj.schema import FAULT_CLASSES

MECHANICAL_CLASSES = ("backlash", "friction", "jam", "struct_weaken")


def window_attribution(
    class_logits: np.ndarray, joint_logits: np.ndarray, severity: np.ndarray | None
) -> np.ndarray:
    """``[K, J]``: per window, the severity attributed to each joint (``class_logits [K, C]``,
    ``joint_logits [K, J]``, ``severity [K]`` or None for a model without a severity head)."""
    return attribution_from_probabilities(
        softmax(np.asarray(class_logits, np.float64)),
        softmax(np.asarray(joint_logits, np.float64)),
        severity,
    )


def mode_attribution(
    class_logits: np.ndarray, joint_logits: np.ndarray, severity: np.ndarray | None
) -> np.ndarray:
    """``[K, M, J]``: :func:`window_attribution` split by mechanical mode
    (``MECHANICAL_CLASSES``); summed over M it is the window's attribution."""
    return mode_probabilities(
        softmax(np.asarray(class_logits, np.float64)),
        softmax(np.asarray(joint_logits, np.float64)),
        severity,
    )


def mode_probabilities(
    p_class: np.ndarray, p_joint: np.ndarray, severity: np.ndarray | None = None
) -> np.ndarray:
    """:func:`mode_attribution` from probabilities (``[K, C]`` over ``FAULT_CLASSES``,
    ``[K, J]``), as the runtime's diagnoses carry them."""
    p_class = np.asarray(p_class, np.float64)
    mech = p_class[:, [FAULT_CLASSES.index(c) for c in MECHANICAL_CLASSES]]
    sev = np.ones(len(mech)) if severity is None else np.clip(np.asarray(severity), 0.0, 1.0)
    return (mech * sev[:, None])[:, :, None] * np.asarray(p_joint, np.float64)[:, None, :]


def attribution_from_probabilities(
    p_class: np.ndarray, p_joint: np.ndarray, severity: np.ndarray | None = None
) -> np.ndarray:
    """:func:`window_attribution` from probabilities (``[K, C]`` over ``FAULT_CLASSES``,
    ``[K, J]``), as the runtime's diagnoses carry them."""
    return mode_probabilities(p_class, p_joint, severity).sum(axis=1)


def isotonic(values: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """The non-decreasing sequence nearest ``values [S]`` in (``weights``-weighted) least
    squares (pool adjacent violators)."""
    v = np.asarray(values, float)
    w_in = np.ones(len(v)) if weights is None else np.asarray(weights, float)
    level: list[float] = []
    weight: list[float] = []
    count: list[int] = []
    for value, w in zip(v, w_in, strict=True):
        level.append(float(value))
        weight.append(float(w))
        count.append(1)
        while len(level) > 1 and level[-2] > level[-1]:
            total = weight[-2] + weight[-1]
            level[-2] = (level[-2] * weight[-2] + level[-1] * weight[-1]) / total
            weight[-2] = total
            count[-2] += count[-1]
            level.pop(), weight.pop(), count.pop()
    return np.repeat(level, count)


def monotone_index(history: np.ndarray) -> np.ndarray:
    """A joint's daily index ``[S]`` (oldest first) read as wear, which never heals: the
    non-decreasing fit of the days so far. Missing days (NaN) are left out of the fit and keep
    NaN. A monitor reads the last value; replayed day by day it gives each day's reading."""
    h = np.asarray(history, float)
    out = np.full(h.shape, np.nan)
    keep = np.isfinite(h)
    out[keep] = isotonic(h[keep])
    return out


@dataclass
class Calibration:
    """A monotone map from the raw index to severity: knots ``x`` (raw) and ``y`` (severity),
    interpolated linearly and held flat beyond the ends. Identity when nothing was fitted."""

    x: list[float]
    y: list[float]

    @classmethod
    def identity(cls) -> Calibration:
        return cls([0.0, 1.0], [0.0, 1.0])

    @classmethod
    def load(cls, path: str | Path) -> Calibration:
        """A calibration saved as JSON ``{"x": [...], "y": [...]}``."""
        try:
            data = json.loads(Path(path).read_text())
            cal = cls([float(v) for v in data["x"]], [float(v) for v in data["y"]])
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise InputError(f"{path}: not a health calibration ({exc})") from None
        if len(cal.x) != len(cal.y) or len(cal.x) < 2 or np.any(np.diff(cal.x) <= 0):
            raise InputError(f"{path}: a calibration needs >= 2 increasing x with one y each")
        return cal

    @classmethod
    def fit(cls, raw: np.ndarray, truth: np.ndarray, knots: int = 12) -> Calibration:
        """Isotonic regression of ``truth`` on ``raw`` (pool-adjacent-violators over the distinct
        raw values, each its days' mean weighted by their number, so that the order of the days
        does not matter), thinned to at most ``knots`` points at the quantiles of the distinct
        values (a raw form that reads most joint-days as exactly 0 would otherwise put every
        knot there)."""
        order = np.lexsort((np.asarray(truth, float), np.asarray(raw, float)))
        xs, ys = np.asarray(raw, float)[order], np.asarray(truth, float)[order]
        ux, first, counts = np.unique(xs, return_index=True, return_counts=True)
        uy = isotonic(np.add.reduceat(ys, first) / counts, counts)
        picks = np.unique(np.linspace(0, len(ux) - 1, knots).round().astype(int))
        return cls(ux[picks].round(6).tolist(), np.clip(uy[picks], 0.0, 1.0).round(6).tolist())

    def __call__(self, raw: np.ndarray | float) -> np.ndarray:
        return np.interp(raw, self.x, self.y)


@dataclass
class SessionHealth:
    """One session's index per joint with its interval (each ``[J]``)."""

    index: np.ndarray
    low: np.ndarray
    high: np.ndarray
    raw: np.ndarray
    windows: int


def session_health(
    attribution: np.ndarray,
    calibration: Calibration | None = None,
    blocks: int = 20,
    draws: int = 200,
    coverage: float = 0.9,
    seed: int = 0,
) -> SessionHealth:
    """The session's index from its windows' ``attribution [K, J]`` (:func:`window_attribution`),
    with a ``coverage`` interval from a block bootstrap (``blocks`` contiguous blocks, resampled
    ``draws`` times with ``seed``)."""
    cal = calibration or Calibration.identity()
    a = np.asarray(attribution, float)
    if len(a) == 0:
        nan = np.full(a.shape[1] if a.ndim == 2 else 6, np.nan)
        return SessionHealth(nan, nan, nan, nan, 0)
    raw = a.mean(axis=0)
    parts = np.array_split(np.arange(len(a)), min(blocks, len(a)))
    means = np.stack([a[p].mean(axis=0) for p in parts])  # [B, J]
    sizes = np.array([len(p) for p in parts], float)
    rng = np.random.default_rng(seed)
    pick = rng.integers(0, len(parts), size=(draws, len(parts)))
    boot = (means[pick] * sizes[pick][..., None]).sum(axis=1) / sizes[pick].sum(axis=1)[:, None]
    tail = (1.0 - coverage) / 2
    low, high = np.quantile(boot, [tail, 1 - tail], axis=0)
    return SessionHealth(cal(raw), cal(low), cal(high), raw, len(a))
