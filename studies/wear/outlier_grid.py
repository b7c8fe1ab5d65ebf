"""How far one channel may pull the signatures' severity read (issue 68, fifth pass).

    python studies/wear/outlier_grid.py outputs/lives/planner_s4{2,3,4} > results/outlier_grid.md

For each run (its cached scores and channel readings, and the signatures the campaign fitted on
the standard corpus's training sessions and the training lives), the chosen index model
(``signature+none+monotone``) reads every life with each limit on one channel's squared misfit
(:data:`robohealth_mj.prognostics.signature.OUTLIER`; none: the read before the limit). Cells:
the wearing joint's index MAE, as the monitor reads it day by day, on the validation lives (where
the limit is chosen), the held-out and the fresh lives. The warnings are not replayed here: the
campaign does that for the limit chosen.
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import replace
from pathlib import Path

import campaign  # this folder's lives campaign: the runs' cached scores and channels
import numpy as np

from robohealth_mj.learn.trainer import CHECKPOINT
from robohealth_mj.prognostics.index_model import IndexModel
from robohealth_mj.reporting.markdown import heading

LIMITS = (math.inf, 9.0, 16.0, 20.0, 25.0, 36.0, 50.0)
CHOSEN = IndexModel("signature", "none", True)


def wearing_joint_mae(scores: dict, indexes: dict) -> dict[str, float]:
    """Per group of lives, the wearing joint's index as the monitor reads it day by day against
    the truth (the campaign's own figure; no warning replayed)."""
    out = {}
    for group, roles in campaign.GROUPS.items():
        views = [
            campaign.LifeView(
                life,
                np.array([d["day"] for d in life["days"]], float),
                np.array([d["truth"] for d in life["days"]]),
                indexes[life["name"]].life(life["days"]),
                {},
            )
            for life in campaign.lives_of(scores, roles)
        ]
        out[group] = campaign.index_figures(views)["wearing_joint_mae"]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument(
        "--standard",
        default="outputs/corpus/standard",
        help="where a run's signatures are fitted if it has none yet (as the campaign fits them)",
    )
    args = ap.parse_args()
    head = ["limit (squared scatters)"]
    head += [f"{run.name}: {group}" for run in args.runs for group in campaign.GROUPS]
    head.append("validation, mean over runs")
    rows: dict[float, list[str]] = {limit: [] for limit in LIMITS}
    validation: dict[float, list[float]] = {limit: [] for limit in LIMITS}
    for run in args.runs:
        scores = json.loads((run / "health_raw.json").read_text())
        for name, life in scores.items():
            life["name"] = name
        campaign.add_channels(scores)
        fitted = campaign.channel_fits(run, [f"{args.standard}/train_*"], scores)
        cal_days = campaign.calibration_days(run / "model" / CHECKPOINT, scores)
        for limit in LIMITS:
            fits = replace(fitted, signatures=replace(fitted.signatures, outlier=limit))
            indexes = campaign.fitted_indexes(CHOSEN, scores, cal_days, fits)
            mae = wearing_joint_mae(scores, indexes)
            rows[limit] += [f"{v:.4f}" for v in mae.values()]
            validation[limit].append(mae["validation"])
    lines = heading("Wearing-joint index MAE by the limit on one channel's misfit", head)
    for limit, cells in rows.items():
        name = "none" if math.isinf(limit) else f"{limit:g}"
        mean = f"{np.mean(validation[limit]):.4f}"
        lines.append("| " + " | ".join([name, *cells, mean]) + " |")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
