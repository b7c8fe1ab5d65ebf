"""Tables of the lives campaign: ``studies/wear/results/*.md`` from each run's ``lives.json``.

    python studies/wear/summarise.py outputs/lives/gbdt_last_s42/lives.json [...] \
        --out studies/wear/results

One row per run for the health index (held-out lives), one per run and estimator for the RUL
metrics and warnings (per mechanical mode and overall), beside each other.
"""

from __future__ import annotations

import argparse
import json
import math
import re
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_text
from robohealth_mj.reporting.markdown import heading
from robohealth_mj.reporting.statistics import mean_pm_std

MODES = ("backlash", "friction", "jam", "struct_weaken")


def _fmt(v: float | None, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return f"{v:.{digits}f}"


def _run(r: dict) -> str:
    return r.get("run", r["variant"])


def _row(cells: list) -> str:
    return "| " + " | ".join(str(c) for c in cells) + " |"


def health_rows(runs: list[dict]) -> list[str]:
    head = ["run", "labels", "index MAE, all joints", "index MAE, wearing joint",
            "band covers truth (±0.02)", "healthy lives MAE", "calibration sessions"]  # fmt: skip
    lines = heading("Health index on held-out lives", head)
    for r in runs:
        h, g = r["health"]["heldout_lives"], r["health"]["healthy_lives"]
        lines.append(_row([
            _run(r), r["labels"], _fmt(h["index_mae_all_joints"]),
            _fmt(h["index_mae_wearing_joint"]), _fmt(h["band_coverage_0.02"]),
            _fmt(g["index_mae_all_joints"]), r["calibration_sessions"],
        ]))  # fmt: skip
    return lines


def _mean(values: list) -> float:
    return float(np.mean(values)) if len(values) else math.nan


def _summary(rows: list[dict]) -> dict:
    al = [r["alpha_lambda_0.5"] for r in rows if r["alpha_lambda_0.5"] is not None]
    ra = [max(r["relative_accuracy_0.5"], -1.0) for r in rows
          if r["relative_accuracy_0.5"] is not None]  # fmt: skip
    lead = [r["warning_lead_days"] for r in rows]
    warned = [v for v in lead if v is not None]
    stretch = [max(r["failure_day"] - r["onset_day"], 1.0) for r in rows]
    estimates = max(sum(len(r["days"]) for r in rows), 1)
    return {
        "lives": len(rows),
        "ph_days": _mean([r["prognostic_horizon"] for r in rows]),
        "ph_fraction": _mean(
            [r["prognostic_horizon"] / s for r, s in zip(rows, stretch, strict=True)]
        ),
        "alpha_lambda": _mean(al),
        "ra": float(np.median(ra)) if ra else math.nan,
        "warned_5": _mean([v is not None and v >= 5 for v in lead]),
        "lead_median": float(np.median(warned)) if warned else math.nan,
        "wall_ms": 1000 * sum(r["wall_s"] for r in rows) / estimates,
    }


def rul_rows(runs: list[dict]) -> list[str]:
    head = ["run", "estimator", "mode", "lives",
            "prognostic horizon, days (share of onset→failure)",
            "alpha-lambda (alpha 0.2, lambda 0.5)", "RA at half-life (median)",
            "warned ≥ 5 days ahead", "lead, median days", "ms / estimate"]  # fmt: skip
    lines = heading("RUL on held-out lives (wearing joint)", head)
    for r in runs:
        estimators = sorted({row["estimator"] for row in r["rul"]}, key=lambda e: e != "trend")
        for est in estimators:
            mine = [row for row in r["rul"] if row["estimator"] == est]
            for mode in (*MODES, "all"):
                rows = mine if mode == "all" else [row for row in mine if row["mode"] == mode]
                if not rows:
                    continue
                s = _summary(rows)
                lines.append(_row([
                    _run(r), est, mode, s["lives"],
                    f"{_fmt(s['ph_days'], 1)} ({_fmt(s['ph_fraction'], 2)})",
                    _fmt(s["alpha_lambda"], 2), _fmt(s["ra"], 2), _fmt(s["warned_5"], 2),
                    _fmt(s["lead_median"], 1), _fmt(s["wall_ms"], 1),
                ]))  # fmt: skip
    return lines


def warning_rows(runs: list[dict]) -> list[str]:
    head = ["run", "lead days", "floor", "healthy arm-days", "days warned",
            "warnings / 100 healthy days", "wrong-joint warning days"]  # fmt: skip
    lines = heading("Wear warnings on healthy arm-days", head)
    for r in runs:
        w = r["healthy"]
        lines.append(_row([
            _run(r), f"{r['lead_days']:g}", f"{r['floor']:g}", w["healthy_arm_days"],
            w["warned_healthy_days"], _fmt(w["warnings_per_100_healthy_days"], 2),
            w["wrong_joint_warning_days"],
        ]))  # fmt: skip
    return lines


def seed_rows(runs: list[dict]) -> list[str]:
    """Runs that differ only in their ``_s<seed>`` suffix, as ``mean ± std`` over the seeds (the
    trend estimator's warnings): the figures the issue's targets are judged on."""
    groups: dict[str, list[dict]] = {}
    for r in runs:
        groups.setdefault(re.sub(r"_s\d+$", "", _run(r)), []).append(r)
    head = ["run", "seeds", "index MAE, all joints", "index MAE, wearing joint",
            "warned ≥ 5 days ahead (trend)", "warnings / 100 healthy days",
            "lead days, floor"]  # fmt: skip
    lines = heading("Over seeds (held-out lives)", head)
    groups = {name: members for name, members in groups.items() if len(members) > 1}
    for name, members in groups.items():
        held = [m["health"]["heldout_lives"] for m in members]
        warned = [_summary([row for row in m["rul"] if row["estimator"] == "trend"])["warned_5"]
                  for m in members]  # fmt: skip
        lines.append(_row([
            name, ", ".join(str(m["seed"]) for m in members),
            mean_pm_std([h["index_mae_all_joints"] for h in held]),
            mean_pm_std([h["index_mae_wearing_joint"] for h in held]),
            f"{mean_pm_std(warned, 2)} ({', '.join(f'{w:.2f}' for w in warned)})",
            mean_pm_std([m["healthy"]["warnings_per_100_healthy_days"] for m in members], 2),
            "; ".join(f"{m['lead_days']:g}, {m['floor']:g}" for m in members),
        ]))  # fmt: skip
    return lines if groups else []


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, default=Path("studies/wear/results"))
    args = ap.parse_args()
    runs = [json.loads(p.read_text()) for p in args.runs]
    seeds = seed_rows(runs)
    text = "\n".join([*health_rows(runs), "", *rul_rows(runs), "", *warning_rows(runs), "",
                      *([*seeds, ""] if seeds else [])])  # fmt: skip
    atomic_write_text(args.out / "lives.md", text)
    print(text)


if __name__ == "__main__":
    main()
