"""Every aggregated row as CSV (mean and std of each metric)."""

from __future__ import annotations

import csv
import io
from typing import Any

from robohealth_mj.reporting.runs import FAULTS
from robohealth_mj.reporting.statistics import COLUMNS


def write_csv(rows: list[dict[str, Any]]) -> str:
    buffer = io.StringIO()
    w = csv.writer(buffer)
    keys = [f"{d}.{m}" for d, m in COLUMNS]
    keys += ["gamma", "coupling_correlation", "best_epoch", "wall_seconds"]
    keys += [f"loc.{f}" for f in FAULTS]
    w.writerow(
        [
            "graph",
            "sensing",
            "placement",
            "variant",
            "window",
            "seeds",
            *[f"{k}.{s}" for k in keys for s in ("mean", "std")],
        ]
    )
    for r in rows:
        w.writerow(
            [
                r["graph"],
                r["sensing"],
                r["placement"],
                r["variant"],
                r["window"],
                len(r["seeds"]),
                *[f"{v:.6g}" for k in keys for v in r[k][:2]],
            ]
        )
    return buffer.getvalue()
