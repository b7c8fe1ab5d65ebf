"""An unseen arm's held-out session, window by window speed scale (issue 65).

    python studies/arms/speed_strata.py [--out DIR] [--arms fr3,xarm7]
        [--variants gbdt,mlp,anomaly_residual] [--own]

Scores each model on the arm's held-out session and splits its windows by the speed scale of
the curriculum segment their last sample belongs to (0.6, 1.0, 1.5): whether a model's loss on
the held-out session sits at one speed. It was the first suspect for ``gbdt`` scoring the unseen
arm's training sessions far above its held-out one; it is not (the held-out loss is even across
speeds), the shared programmes are (``validation_sessions.py``). Reads the runs of
``run_unseen_sessions.sh`` as trained (or, with ``--own``, the arm's own models of
``campaign.py --stages own``); means over the seeds found.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from class_gaps import seed_runs  # this folder's: one arm's runs of a variant, by seed

from robohealth_mj.data.read import read_samples
from robohealth_mj.learn.evaluation import score_checkpoint
from robohealth_mj.learn.metrics import compute_metrics


def strata(run: Path) -> dict[float, tuple[float, float, float]]:
    """Speed scale -> (share of windows, accuracy, localisation) on the run's held-out session."""
    data = json.loads((run / "eval_heldout.json").read_text())["data"]
    scored = score_checkpoint(run / "best.ckpt", data, device="cpu")
    files = scored.files
    if len(files) != 1:
        raise SystemExit(f"{run}: expected one held-out recording, got {len(files)}")
    speeds = np.array([s.segment["speed_scale"] for s in read_samples(files[0])])
    # the recording's rows are its samples in file order; a window takes its last sample's label
    ends = scored.windows.start + scored.windows.window - 1
    speed = speeds[scored.rec.sample_index[ends]]
    p = scored.predictions
    called = (p.class_logits.argmax(1), p.joint_logits.argmax(1))
    truth = (p.true_class, p.true_joint, p.active, p.true_severity)
    out = {}
    for s in np.unique(speed):
        mask = speed == s
        m = compute_metrics(*(a[mask] for a in (*called, *truth)))
        out[float(s)] = (float(mask.mean()), m["accuracy"], m["localisation_accuracy"])
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("outputs/campaign_family_plus2"))
    parser.add_argument("--arms", default="fr3,xarm7")
    parser.add_argument("--variants", default="gbdt,mlp,anomaly_residual")
    parser.add_argument("--own", action="store_true", help="the arm's own models instead")
    args = parser.parse_args()
    root = args.out / "full" / ("own" if args.own else "loao")
    print("| arm | variant | seeds | speed scale | share of windows | accuracy | localisation |")
    print("|---|---|---|---|---|---|---|")
    for arm in args.arms.split(","):
        for variant in args.variants.split(","):
            runs = seed_runs(root, arm, variant)
            if not runs:
                continue
            per_seed = [strata(run) for _, run in sorted(runs.items())]
            for s in sorted(per_seed[0]):
                share, acc, loc = np.mean([r[s] for r in per_seed], axis=0)
                print(f"| {arm} | {variant} | {len(per_seed)} | {s:g} | {share:.3f} | "
                      f"{acc:.3f} | {loc:.3f} |")  # fmt: skip


if __name__ == "__main__":
    main()
