"""The trend estimator's window (sessions in its line), chosen on the validation lives.

    python studies/wear/trend_window.py outputs/lives/gbdt_standard+lives_levels_s42 [...]

For each run and window: the lead time and floor tuned as the campaign tunes them (on the
validation lives, or the training lives where a corpus has none), those lives' share warned at
least 5 days ahead and mean prognostic horizon and alpha-lambda accuracy (what chooses), and, for
the record only, the held-out lives warned at least 5 days ahead and the warnings per 100 healthy
arm-days. Scores are the runs'
cached ``health_raw.json``; nothing is retrained.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
from pathlib import Path

import numpy as np

from robohealth_mj.prognostics.health import Calibration
from robohealth_mj.prognostics.rul import TrendRul
from robohealth_mj.reporting.markdown import heading

WINDOWS = (5, 6, 8, 10, 12)


def _campaign():
    path = Path(__file__).with_name("campaign.py")
    spec = importlib.util.spec_from_file_location("lives_campaign", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", type=Path)
    args = ap.parse_args()
    c = _campaign()
    head = ["run", "window", "tuned on", "lead days, floor", "tuning: warned ≥ 5 d",
            "tuning: PH days", "tuning: alpha-lambda", "held-out warned ≥ 5 d",
            "held-out: healthy warnings / 100 d"]  # fmt: skip
    print("\n".join(heading("Trend window, chosen on the validation lives", head)))
    for run in args.runs:
        scores = json.loads((run / "health_raw.json").read_text())
        cal = Calibration(**json.loads((run / "calibration.json").read_text()))
        role = c.tuning_role(scores)
        train = c.as_held_out(scores, role)
        for window in WINDOWS:
            est = TrendRul(threshold=0.8, window=window)
            t = c.tune_warning(scores, cal, est)
            lead, floor = t["lead_days"], t["floor"]
            tr = c.rul_rows(train, cal, {"trend": est}, lead, floor)
            held = c.rul_rows(scores, cal, {"trend": est}, lead, floor)
            healthy = c.healthy_warnings(scores, cal, est, lead, floor)
            warned, tuned = c.warned_share(held), c.warned_share(tr)
            cells = [
                run.name, window, role, f"{lead:g}, {floor:g}", f"{tuned:.2f}",
                f"{np.mean([r['prognostic_horizon'] for r in tr]):.1f}",
                f"{np.mean([r['alpha_lambda_0.5'] for r in tr]):.2f}", f"{warned:.2f}",
                f"{healthy['warnings_per_100_healthy_days']:.2f}",
            ]  # fmt: skip
            print("| " + " | ".join(str(x) for x in cells) + " |", flush=True)


if __name__ == "__main__":
    main()
