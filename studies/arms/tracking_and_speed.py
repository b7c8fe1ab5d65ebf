"""Each arm's healthy tracking error and recorder speed, from its corpus (issue 65's targets:
tracking within 2x the UR5e's at the same relative speed, recorder speed per simulated second
within 25 % of the UR5e's).

    python studies/arms/tracking_and_speed.py [--corpus outputs/corpus/arms] [--arms ur5e,fr3,...]

Reads each arm's ten healthy minutes (``healthy_commissioning_seed940``: faults off, the
standard curriculum, which sweeps every joint at the same fraction of its own speed limit, so
the arms move at the same relative speed) and its eight training sessions' wall time (recorded
two at a time on the same machine, the corpus's jobs; nan where an arm's folder holds only its
healthy minutes). Prints a markdown table.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

HEALTHY = "healthy_commissioning_seed940"


def _manifest(session: Path) -> dict:
    return json.loads((session / "manifest.json").read_text())


def arm_row(root: Path) -> dict:
    """Tracking RMS (median and worst joint, mrad) over the healthy minutes; recorder wall time
    per simulated second over the training sessions."""
    healthy = _manifest(root / HEALTHY)
    rms = np.array(list(healthy["stats"]["tracking_rms_rad"].values())) * 1e3
    sessions = [_manifest(p) for p in sorted(root.glob("train_*"))]
    wall = sum(m["wall_s"] for m in sessions)
    simulated = sum(m["sample_count"] / m["rates"]["tick_hz"] for m in sessions)
    return {"joints": len(rms), "median_mrad": float(np.median(rms)),
            "worst_mrad": float(rms.max()),
            "wall_per_sim_s": wall / simulated if sessions else float("nan")}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--corpus", type=Path, default=Path("outputs/corpus/arms"))
    parser.add_argument("--arms", default="ur5e,fr3,iiwa14,gen3,xarm7")
    args = parser.parse_args()
    arms = args.arms.split(",")
    rows = {arm: arm_row(args.corpus / arm) for arm in arms}
    ref = rows[arms[0]]
    print(f"| arm | joints | tracking RMS, median joint (mrad) | worst joint (mrad) | worst / "
          f"{arms[0]}'s | recorder wall s per simulated s | / {arms[0]}'s |\n"
          "|---|---|---|---|---|---|---|")  # fmt: skip
    for arm, r in rows.items():
        print(f"| {arm} | {r['joints']} | {r['median_mrad']:.3f} | {r['worst_mrad']:.3f} | "
              f"{r['worst_mrad'] / ref['worst_mrad']:.2f} | {r['wall_per_sim_s']:.4f} | "
              f"{r['wall_per_sim_s'] / ref['wall_per_sim_s']:.2f} |")  # fmt: skip


if __name__ == "__main__":
    main()
