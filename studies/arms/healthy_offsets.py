"""Where an unseen arm's healthy running sits against its training arms', place by place: the
measurement that found the KUKA's sensor packages mounted in another frame.

    python studies/arms/healthy_offsets.py --campaign outputs/campaign_seven [--top 6]
        [--corpus outputs/corpus/arms]

For each leave-one-arm-out ``gbdt`` model of the campaign (its checkpoint names its training
data and carries its normalisation), the unseen arm's ten healthy minutes and the training arms'
healthy ticks are z-scored alike; each node and channel's offset is the difference of the two
healthy means in units of the training arms' healthy spread. The largest per arm are printed
with the two raw means: an offset of hundreds of spreads on a sensor's gravity channel is a
frame, not a fault.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.data.arrays import expand_paths
from robohealth_mj.deploy.renormalise import FLAT, healthy_moments
from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checked, load_checkpoint
from robohealth_mj.reporting.markdown import heading

RUN = "structural/full/C0/gbdt/w32/seed42"


def offsets(ckpt_path: Path, healthy: Path) -> list[tuple[float, str, str, float, float, float]]:
    """``(offset, node, channel, training mean, arm mean, spread ratio)`` for every live node
    and channel, largest offset first."""
    ckpt = load_checkpoint(ckpt_path)
    ref = load_checked(ckpt, expand_paths(ckpt["config"]["data"]["train"]))
    arm = load_checked(ckpt, expand_paths([str(healthy)]))
    graph = graph_from_checkpoint(ckpt)
    (ref_mean, spread), (arm_mean, arm_spread) = (
        healthy_moments(graph.transform(x)) for x in (ref.x[~ref.active], arm.x)
    )
    live = spread > FLAT
    unit = np.where(live, spread, 1.0)
    shift = np.where(live, (arm_mean - ref_mean) / unit, 0.0)
    ratio = np.where(live, arm_spread / unit, 1.0)
    rows = []
    for n, f in zip(*np.nonzero(live), strict=True):
        rows.append((float(shift[n, f]), graph.node_names[n], schema.FEATURE_NAMES[f],
                     float(ref_mean[n, f]), float(arm_mean[n, f]), float(ratio[n, f])))  # fmt: skip
    return sorted(rows, key=lambda r: -abs(r[0]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaign", type=Path, required=True, help="a campaign.py --out root")
    parser.add_argument("--corpus", type=Path, default=Path("outputs/corpus/arms"))
    parser.add_argument("--top", type=int, default=6)
    args = parser.parse_args()
    lines = heading(
        f"Healthy offsets of each unseen arm ({args.campaign}, corpus {args.corpus})",
        ["unseen arm", "node", "channel", "offset (training spreads)", "training mean",
         "arm mean", "spread ratio"],
    )  # fmt: skip
    loao = args.campaign / "full" / "loao"
    for arm_dir in sorted(p for p in loao.iterdir() if (p / RUN / "best.ckpt").is_file()):
        healthy = args.corpus / arm_dir.name / "healthy_commissioning_seed940"
        for shift, node, channel, ref_mean, arm_mean, ratio in offsets(
            arm_dir / RUN / "best.ckpt", healthy
        )[: args.top]:
            lines.append(
                f"| {arm_dir.name} | {node} | {channel} | {shift:+.1f} | {ref_mean:+.3f} | "
                f"{arm_mean:+.3f} | {ratio:.2f} |"
            )
    print("\n".join(lines))


if __name__ == "__main__":
    main()
