"""How much of a seven-joint arm's gap to the UR5e is a fault no sensor could see? (issue 65)

    python studies/arms/observable.py [--own DIR] [--arms ur5e,fr3,iiwa14,gen3,xarm7]
        [--variants gbdt,anomaly_residual]

Friction and backlash act only on a turning joint (:mod:`robohealth_mj.data.observability`).
The held-out sessions draw where each fault lands and what the arm does meanwhile, so the share
of motion-only fault windows whose joint stood still differs from arm to arm; on those windows no
channel changes and every model misses them. Each arm's own models (``campaign.py --stages
own``) are scored again on their held-out session with the package's own rule for what a window
can show (``labels=visible observability=motion``, as ``evaluate`` and the monitor offer), cached
as ``eval_heldout_visible.json`` beside each run, and the table sets both scores beside the
UR5e's (means over the seeds every arm has).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from class_gaps import seed_runs  # this folder's: one arm's runs of a variant, by seed

from robohealth_mj.data.observability import MOTION_ONLY_FAULTS
from robohealth_mj.learn.evaluation import evaluate_checkpoint, write_evaluation

REFERENCE = "ur5e"


def visible_score(run: Path) -> dict:
    """The run scored on its held-out session by what each window can show (computed once)."""
    cached = run / "eval_heldout_visible.json"
    if not cached.is_file():
        data = json.loads((run / "eval_heldout.json").read_text())["data"]
        result = evaluate_checkpoint(run / "best.ckpt", data, "cpu", "visible", "motion")
        write_evaluation(result, cached.with_suffix(""))
    return json.loads(cached.read_text())["metrics"]


def unseen_share(metrics: dict) -> float:
    """The share of faulted windows that carry a motion-only fault on a joint that stood still."""
    still = metrics["by_motion"]["still"]["per_class"]
    hidden = sum(still[c]["support"] for c in MOTION_ONLY_FAULTS if c in still)
    return hidden / metrics["faulted_windows"]


def arm_figures(own: Path, arm: str, variant: str) -> np.ndarray | None:
    """Seed means of [acc., loc., observable acc., observable loc., unseen share, seeds]."""
    rows = []
    for _, run in sorted(seed_runs(own, arm, variant).items()):
        as_labelled = json.loads((run / "eval_heldout.json").read_text())["metrics"]
        visible = visible_score(run)
        rows.append(
            [
                as_labelled["accuracy"],
                as_labelled["localisation_accuracy"],
                visible["accuracy"],
                visible["localisation_accuracy"],
                unseen_share(as_labelled),
            ]
        )
    return np.array([*np.mean(rows, axis=0), len(rows)]) if rows else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--own", type=Path, default=Path("outputs/campaign_seven/full/own"))
    parser.add_argument("--arms", default="ur5e,fr3,iiwa14,gen3,xarm7")
    parser.add_argument("--variants", default="gbdt,anomaly_residual")
    args = parser.parse_args()
    print(
        "| arm | variant | seeds | motion-only faults on a still joint | as labelled: acc. / loc."
        " | gap to UR5e | what the windows show: acc. / loc. | gap to UR5e |\n"
        "|---|---|---|---|---|---|---|---|"
    )
    for variant in args.variants.split(","):
        reference = arm_figures(args.own, REFERENCE, variant)
        for arm in args.arms.split(","):
            f = arm_figures(args.own, arm, variant)
            if f is None or reference is None:
                continue
            gap = 100 * (f[:4] - reference[:4])
            print(
                f"| {arm} | {variant} | {f[5]:.0f} | {f[4]:.1%} | {f[0]:.3f} / {f[1]:.3f} | "
                f"{gap[0]:+.1f} / {gap[1]:+.1f} | {f[2]:.3f} / {f[3]:.3f} | "
                f"{gap[2]:+.1f} / {gap[3]:+.1f} |"
            )


if __name__ == "__main__":
    main()
