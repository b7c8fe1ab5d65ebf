"""The trend estimator's window (sessions in its line) under the chosen index model, chosen on the
validation lives.

    python studies/wear/trend_window.py outputs/lives/planner_s42 [...]

For each run (its ``lives.json`` names the chosen index model) and window: the lead time and floor
tuned as the campaign tunes them, the validation lives' share first warned in band (what chooses),
and, for the record only, the held-out and fresh lives' share and the warnings per 100 healthy
arm-days. Scores are the runs' cached ``health_raw.json``; nothing is retrained.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import campaign  # this folder's lives campaign: scoring, calibration, the warning

from robohealth_mj.prognostics.index_model import VARIANTS
from robohealth_mj.prognostics.rul import TrendRul
from robohealth_mj.reporting.markdown import heading

WINDOWS = (5, 6, 8, 10, 12, 15)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", type=Path)
    args = ap.parse_args()
    c = campaign
    head = ["run", "index model", "window", "lead days, floor", "validation: in band",
            "held-out: in band", "fresh: in band", "held-out: warnings / 100 d"]  # fmt: skip
    print("\n".join(heading("Trend window, chosen on the validation lives", head)))
    for run in args.runs:
        scores = json.loads((run / "health_raw.json").read_text())
        for name, life in scores.items():
            life["name"] = name
        chosen = json.loads((run / "lives.json").read_text())["chosen"]
        model = next(m for m in VARIANTS if m.name == chosen)
        c.add_channels(scores)
        channels = c.channel_fits(run, [], scores)  # the run's, fitted when it ran
        cal_days = c.calibration_days(run / "model" / "best.ckpt", scores)
        for window in WINDOWS:
            est = TrendRul(threshold=0.8, window=window)
            row = c.evaluate_variant(model, scores, cal_days, est, channels)
            g, w = row["groups"], row["warning"]
            cells = [
                run.name, chosen, window, f"{w['lead_days']:g}, {w['floor']:g}",
                f"{g['validation']['warnings']['in_band']:.2f}",
                f"{g['held_out']['warnings']['in_band']:.2f}",
                f"{g['fresh']['warnings']['in_band']:.2f}",
                f"{g['held_out']['warnings']['warnings_per_100_healthy_days']:.2f}",
            ]  # fmt: skip
            print("| " + " | ".join(str(x) for x in cells) + " |", flush=True)


if __name__ == "__main__":
    main()
