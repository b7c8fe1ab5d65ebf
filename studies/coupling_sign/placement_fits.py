"""The sign-pinned coupling's placement on many placements, without training (issue 69).

    python studies/coupling_sign/placement_fits.py [--corpus DIR] [--out FILE]
        [--placements 1:3,2:4,...] [--seeds 42,43,44] [--profiles full,retrofit]

Under ``model.coupling_fit=motion`` training sets ``C`` once, before the first step, to the
motion estimate on the healthy running its training windows cover, and never changes it; so
``C`` depends on the placement, the sensing profile and the seed's run-aware split, and on
nothing a model learns (nor on the reconstruction weight). This measures it for each placement
(``graph.coupling_seed:coupling_sensors``), profile and seed exactly as ``prepare`` does:
corr(C, C0), its sign, and each joint row's correlation. The fit reads the joints' position and
velocity and the sensor channels, which the retrofit profile keeps: its ``C`` is the full
profile's (the trained runs agree to 3 decimals).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from hydra.utils import instantiate
from tqdm import tqdm

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.config import compose_config
from robohealth_mj.data.arrays import expand_paths, load_recordings
from robohealth_mj.data.graphs import coupling_correlation, harness_graph
from robohealth_mj.data.windows import label_windows, make_windows, run_aware_split
from robohealth_mj.learn.motion_placement import training_placement

PLACEMENTS = "1:3,2:4,3:6,4:5,5:4,6:3,7:4,8:5,9:6,10:5"  # seed:sensors, 3 to 6 sensors


def row_correlations(c: np.ndarray, truth: np.ndarray) -> list[float]:
    """Each joint row's correlation, as :func:`coupling_correlation` averages them (a row the
    fit left empty: 0)."""
    return [round(coupling_correlation(a[None], b[None]), 3) for a, b in zip(c, truth, strict=True)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--corpus", type=Path, default=Path("outputs/corpus/standard"))
    parser.add_argument("--out", type=Path, default=Path("studies/coupling_sign/results/fits.json"))
    parser.add_argument("--placements", default=PLACEMENTS)
    parser.add_argument("--seeds", default="42,43,44")
    parser.add_argument("--profiles", default="full,retrofit")
    args = parser.parse_args()
    cfg = compose_config("train", ["graph=harness", "window=32"])
    rec = load_recordings(expand_paths([str(args.corpus / "train_*")]))
    placements = [tuple(int(v) for v in p.split(":")) for p in args.placements.split(",")]
    seeds = [int(s) for s in args.seeds.split(",")]
    rows = []
    jobs = [(profile, seed) for profile in args.profiles.split(",") for seed in seeds]
    for profile, seed in tqdm(jobs, desc="profile x seed"):
        sensing = instantiate(compose_config("train", [f"sensing={profile}"]).sensing)
        base = harness_graph(arm=rec.graph).with_sensing(sensing)
        labelled = label_windows(base.relabel(rec), int(cfg.window), str(cfg.labels))
        windows = make_windows(labelled, int(cfg.window), cfg.stride)
        train = run_aware_split(labelled, windows, seed)["train"]
        for placement, sensors in placements:
            world = harness_graph(coupling_seed=placement, coupling_sensors=sensors, arm=rec.graph)
            world = world.with_sensing(sensing)
            c = training_placement(labelled, train, world)
            rows.append({
                "placement": f"seed{placement}_m{sensors}", "sensing": profile, "seed": seed,
                "coupling_correlation": round(coupling_correlation(c, world.coupling), 4),
                "rows": row_correlations(c, world.coupling), "coupling": c.round(4).tolist(),
                "truth": world.coupling.round(4).tolist(),
            })  # fmt: skip
    atomic_write_json(args.out, {"corpus": str(args.corpus), "fits": rows})
    corr = np.array([r["coupling_correlation"] for r in rows])
    summary = {"fits": len(rows), "mean": round(float(corr.mean()), 3)}
    summary.update(min=round(float(corr.min()), 3), negative=int((corr <= 0).sum()))
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
