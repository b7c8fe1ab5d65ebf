"""Where the severity head's error on the standard held-out session comes from: faulted windows
split by whether the model got the fault (class and joint) right, and by the fault's level.

    python studies/wear/severity_strata.py outputs/severity_labels/gbdt_last/best.ckpt \
        outputs/corpus/standard/heldout_seed900 [--labels last]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from robohealth_mj.learn.evaluation import score_checkpoint


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("ckpt")
    ap.add_argument("data")
    ap.add_argument("--labels", default=None)
    args = ap.parse_args()
    p = score_checkpoint(args.ckpt, args.data, device="cpu", labels=args.labels).predictions
    faulted = p.active
    right = (p.class_logits.argmax(1) == p.true_class) & (p.joint_logits.argmax(1) == p.true_joint)
    err = np.abs(p.severity - p.true_severity)
    out = {"faulted_windows": int(faulted.sum()), "mae_faulted": float(err[faulted].mean())}
    for name, mask in (("fault_right", faulted & right), ("fault_missed", faulted & ~right)):
        out[name] = {"windows": int(mask.sum()), "mae": float(err[mask].mean())}
        for level in sorted({round(float(s), 6) for s in p.true_severity[mask]}):
            at = mask & np.isclose(p.true_severity, level)
            out[name][f"mae_at_{level:g}"] = float(err[at].mean())
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
