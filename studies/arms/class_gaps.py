"""Which classes make an unseen arm's gap to its own model? (issue 65)

    python studies/arms/class_gaps.py [--out DIR] [--own DIR] [--arms fr3,xarm7]
        [--variants gbdt,mlp,anomaly_residual] [--normalisation shift]
        [--baseline-normalisation none] [--as-trained]

For each unseen arm and model: each class's recall on the arm's held-out session, from the arm's
own model and from the leave-one-arm-out model commissioned on its ten healthy minutes (means of
the seeds both have), and the points of accuracy the class's change moves: the change in windows
called right over all windows. The columns add up to the accuracy gap, so they say where a gap
that commissioning leaves comes from. ``gbdt`` reads its models commissioned with
``--baseline-normalisation``, the networks with ``--normalisation`` (each by validation's recipe);
``--as-trained`` reads the unseen arm's models as trained instead (``campaign.py
--unseen-sessions``, where validation picks no commissioning).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from campaign import commissioned_dir  # this folder's campaign: where each model is written

from robohealth_mj.deploy.renormalise import MATCHES


def class_counts(eval_json: Path) -> dict[str, tuple[float, float]]:
    """``class -> (windows called right, windows)`` over the held-out session."""
    per_class = json.loads(eval_json.read_text())["metrics"]["per_class"]
    return {c: (m["recall"] * m["support"], m["support"]) for c, m in per_class.items()}


def seed_runs(root: Path, arm: str, variant: str) -> dict[str, Path]:
    """``seed -> run directory`` of one arm and variant under a campaign stage root."""
    runs = root.glob(f"{arm}/*/full/*/{variant}/w32/seed*")
    return {run.name: run for run in runs if (run / "eval_heldout.json").is_file()}


def gaps(own: dict[str, Path], loao: dict[str, Path], commissioned: str) -> dict[str, list]:
    """``class -> [own recall, unseen recall, points of accuracy]`` averaged over the seeds
    both stages have (the unseen arm's models as commissioned)."""
    rows: dict[str, list[np.ndarray]] = {}
    for seed in sorted(own.keys() & loao.keys()):
        after = loao[seed] / commissioned / "eval_heldout.json"
        if not after.is_file():
            continue
        mine, theirs = class_counts(own[seed] / "eval_heldout.json"), class_counts(after)
        total = sum(n for _, n in mine.values())
        for c, (right, n) in mine.items():
            moved = (theirs[c][0] - right) / total
            rows.setdefault(c, []).append(np.array([right / n, theirs[c][0] / n, 100 * moved]))
    return {c: [*np.mean(values, axis=0), len(values)] for c, values in rows.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("outputs/campaign_family_fixed"))
    parser.add_argument("--own", type=Path, default=Path("outputs/campaign_seven"))
    parser.add_argument("--arms", default="fr3,xarm7")
    parser.add_argument("--variants", default="gbdt,mlp,anomaly_residual")
    parser.add_argument("--normalisation", default="shift", choices=MATCHES)
    parser.add_argument("--baseline-normalisation", default="none", choices=MATCHES)
    parser.add_argument("--as-trained", action="store_true", help="the models as trained")
    args = parser.parse_args()
    read = "as trained" if args.as_trained else "commissioned"
    print(f"| unseen arm | variant | seeds | class | own recall | unseen, {read} | "
          "points of accuracy |\n|---|---|---|---|---|---|---|")  # fmt: skip
    for arm in args.arms.split(","):
        for variant in args.variants.split(","):
            norm = args.baseline_normalisation if variant == "gbdt" else args.normalisation
            commissioned = (
                "." if args.as_trained else commissioned_dir(Path(), normalisation=norm).name
            )
            own = seed_runs(args.own / "full" / "own", arm, variant)
            loao = seed_runs(args.out / "full" / "loao", arm, variant)
            rows = gaps(own, loao, commissioned)
            if not rows:
                continue
            total = sum(r[2] for r in rows.values())
            for c, (mine, theirs, points, seeds) in rows.items():
                print(f"| {arm} | {variant} | {seeds:.0f} | {c} | {mine:.3f} | {theirs:.3f} | "
                      f"{points:+.1f} |")  # fmt: skip
            print(f"| {arm} | {variant} | | **all** | | | **{total:+.1f}** |")


if __name__ == "__main__":
    main()
