"""Statistics over seeds: mean ± std of a metric, one row per (setting, model, window), and the
per-seed paired differences the research questions' tables report."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from robohealth_mj.reporting.runs import FAULTS, grouped, value_at

COLUMNS = (
    ("heldout", "accuracy"),
    ("heldout", "fault_present_accuracy"),
    ("heldout", "macro_f1"),
    ("heldout", "localisation_accuracy"),
    ("probe", "accuracy"),
    ("probe", "localisation_accuracy"),
)


def mean_std(values: list[float | None]) -> tuple[float, float, int]:
    v = np.array([x for x in values if x is not None and np.isfinite(x)], dtype=float)
    if not len(v):
        return float("nan"), float("nan"), 0
    return float(v.mean()), float(v.std()), len(v)


def fmt_stat(stat: tuple[float, float, int], digits: int = 3) -> str:
    mean, std, n = stat
    return "—" if n == 0 else f"{mean:.{digits}f} ± {std:.{digits}f}"


def mean_pm_std(values: list[float | None], digits: int = 3) -> str:
    """``mean ± std`` of the finite values, as every results table prints it (``—`` if none)."""
    return fmt_stat(mean_std(values), digits)


def aggregate(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    rows = []
    for (setting, label, window), members in grouped(runs):
        row: dict[str, Any] = {
            "setting": setting,
            "graph": members[0]["graph"],
            "sensing": members[0]["sensing"],
            "placement": members[0]["placement"],
            "variant": label,
            "window": window,
            "seeds": sorted(m["seed"] for m in members),
        }
        for dataset, metric in COLUMNS:
            row[f"{dataset}.{metric}"] = mean_std([value_at(m, dataset, metric) for m in members])
        row["gamma"] = mean_std([m.get("gamma") for m in members])
        row["coupling_correlation"] = mean_std([m.get("coupling_correlation") for m in members])
        row["best_epoch"] = mean_std([m["best_epoch"] for m in members])
        row["wall_seconds"] = mean_std([m.get("wall_seconds") for m in members])
        for fault in FAULTS:
            row[f"loc.{fault}"] = mean_std(
                [value_at(m, "heldout", "per_class", fault, "localisation") for m in members]
            )
        rows.append(row)
    return rows


def paired_cells(
    effect: Callable[[int, str], float], seeds: list[int], metrics: tuple[str, ...]
) -> list[str]:
    """One ``mean ± std`` cell per metric of a per-seed difference ``effect(seed, metric)``:
    the paired comparison both research questions' tables make."""
    cells = []
    for metric in metrics:
        mean, std, _ = mean_std([effect(seed, metric) for seed in seeds])
        cells.append(f"{mean:+.3f} ± {std:.3f}")
    return cells
