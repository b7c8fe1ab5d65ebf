"""The metric set of thesis §2.7, overall, by severity, and by whether the faulted joint moved.

Fault presence: the class argmax is anything but ``none``. Localisation: the joint argmax against
the injected joint, on windows whose final snapshot has an active fault.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from sklearn.metrics import confusion_matrix, precision_recall_fscore_support

from robohealth_mj.schema import FAULT_CLASSES

if TYPE_CHECKING:
    from robohealth_mj.learn.predict import Predictions


def _scalar_metrics(
    pred_class, pred_joint, true_class, true_joint, active, severity_true, severity_pred
) -> dict[str, Any]:
    labels = list(range(len(FAULT_CLASSES)))
    out: dict[str, Any] = {"windows": len(true_class)}
    if not len(true_class):
        return out
    out["accuracy"] = float(np.mean(pred_class == true_class))
    out["fault_present_accuracy"] = float(np.mean((pred_class != 0) == (true_class != 0)))
    p, r, f, support = precision_recall_fscore_support(
        true_class, pred_class, labels=labels, zero_division=0
    )
    present = support > 0
    out["macro_f1"] = float(f[present].mean()) if present.any() else float("nan")
    out["per_class"] = {
        name: {
            "precision": float(p[i]),
            "recall": float(r[i]),
            "f1": float(f[i]),
            "support": int(support[i]),
            **_per_class_extras(
                active & (true_class == i), pred_joint, true_joint, severity_true, severity_pred
            ),
        }
        for i, name in enumerate(FAULT_CLASSES)
    }
    out["faulted_windows"] = int(active.sum())
    out["localisation_accuracy"] = (
        float(np.mean(pred_joint[active] == true_joint[active])) if active.any() else float("nan")
    )
    out["confusion_matrix"] = confusion_matrix(true_class, pred_class, labels=labels).tolist()
    if severity_pred is not None:
        error = np.abs(severity_pred - severity_true)
        out["severity_mae"] = float(np.mean(error))
        if active.any():
            out["severity_mae_faulted"] = float(np.mean(error[active]))
    return out


def _per_class_extras(
    mask: np.ndarray, pred_joint, true_joint, severity_true, severity_pred
) -> dict[str, float]:
    """On one class's faulted windows: localisation (what each fault hides from the sensors a
    profile keeps) and, with a severity head, the severity error."""
    if not mask.any():
        return {}
    out = {"localisation": float(np.mean(pred_joint[mask] == true_joint[mask]))}
    if severity_pred is not None:
        out["severity_mae"] = float(np.mean(np.abs(severity_pred[mask] - severity_true[mask])))
    return out


def compute_metrics(
    pred_class: np.ndarray,
    pred_joint: np.ndarray,
    true_class: np.ndarray,
    true_joint: np.ndarray,
    active: np.ndarray,
    severity: np.ndarray,
    severity_pred: np.ndarray | None = None,
    target_moving: np.ndarray | None = None,
) -> dict[str, Any]:
    """All metrics, plus the same metrics on the faulted windows of each injected severity level
    and, given ``target_moving [K]``, on faulted windows whose faulted joint moved or stood
    still."""
    args = (pred_class, pred_joint, true_class, true_joint, active, severity, severity_pred)
    result = _scalar_metrics(*args)
    strata = {}
    for level in sorted({float(round(s, 6)) for s in severity[active]}):
        mask = active & np.isclose(severity, level)
        strata[f"{level:g}"] = _scalar_metrics(*(a[mask] if a is not None else None for a in args))
    result["by_severity"] = strata
    if target_moving is not None:
        result["by_motion"] = {
            name: _scalar_metrics(*(a[active & m] if a is not None else None for a in args))
            for name, m in (("moving", target_moving), ("still", ~target_moving))
        }
    return result


def detection_rates(metrics: dict[str, Any]) -> tuple[float, float]:
    """From a metric set's confusion matrix: the share of healthy windows called any fault (the
    false calls) and of faulted windows called any fault (the detections), whatever class."""
    cm = np.asarray(metrics["confusion_matrix"], dtype=float)
    healthy = 1.0 - cm[0, 0] / max(cm[0].sum(), 1.0)
    faulted = cm[1:, 1:].sum() / max(cm[1:].sum(), 1.0)
    return float(healthy), float(faulted)


def flat_rows(metrics: dict[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    """Scalar metrics as ``(name, value)`` rows for CSV (nested dicts become dotted names)."""
    rows = []
    for key, value in metrics.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            rows += flat_rows(value, f"{name}.")
        elif isinstance(value, int | float):
            rows.append((name, value))
    return rows


def metrics_of(pred: Predictions, target_moving: np.ndarray | None = None) -> dict[str, Any]:
    """The metric set of one model's predictions (argmax class and joint)."""
    return compute_metrics(
        pred.class_logits.argmax(1),
        pred.joint_logits.argmax(1),
        pred.true_class,
        pred.true_joint,
        pred.active,
        pred.true_severity,
        pred.severity,
        target_moving,
    )
