"""Placement self-calibration, then training on the placement found (ablation).

The motion fit (``deploy/recouple.py``) finds a retrofit kit's placement from ten healthy
minutes of the arm (no labels). Here a model is trained from scratch on the training corpus
re-mixed by that *estimated* placement (``graph.coupling_file``; the corpus keeps every joint's
package, which is also what the motion fit reads), and scored on data mixed by the *true*
placement: first the validation runs of the training sessions, where the sensors' z-scores are
chosen (the training's, or refitted on the arm's healthy running), then the held-out session.
Against models trained on the true placement. Retrofit, W = 32, seed 42.

    CORPUS=... .venv/bin/python studies/stock_arm/self_calibration_retrain.py estimate POOL_CKPT
    (then train outputs/selfcal/retrained/seed<S> on each estimate: studies/stock_arm/run.sh)
    CORPUS=... .venv/bin/python studies/stock_arm/self_calibration_retrain.py \\
        > studies/stock_arm/results/self_calibration_retrain.md

``estimate`` writes the motion fit's C (unpruned, as when this ablation was run) for each
placement to ``outputs/selfcal/estimated/seed<S>.json`` (the pool checkpoint names the training
data the fit reads); the second form scores the runs trained on them.
"""

from __future__ import annotations

import json
import os
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import torch

from robohealth_mj.data.arrays import Recording, expand_paths, load_recordings
from robohealth_mj.data.graphs import coupling_correlation, harness_graph
from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checkpoint
from robohealth_mj.learn.evaluation import score_under_placement
from robohealth_mj.learn.motion_placement import motion_estimate

CORPUS = os.environ.get("CORPUS", "outputs/corpus/standard")
RUNS = Path("outputs/thesis_physics/harness/retrofit")
SELFCAL = Path("outputs/selfcal")
PLACEMENTS = [2, 5, 21, 22, 23]
torch.set_num_threads(1)
held_all = load_recordings([f"{CORPUS}/heldout_seed900/graphs.jsonl"])
healthy = load_recordings([f"{CORPUS}/healthy_nominal_seed940/graphs.jsonl"])


def score(
    ckpt: dict, truth: np.ndarray, refit: bool, data: Recording | None = None
) -> tuple[float, float]:
    """Accuracy and localisation on the held-out session (or ``data``: the validation runs of
    the training sessions) mixed by ``truth``; with ``refit`` the sensors are z-scored on the
    arm's healthy running (what commissioning can measure)."""
    m = score_under_placement(ckpt, held_all if data is None else data, truth,
                              healthy=healthy if refit else None,
                              validation_only=data is not None)  # fmt: skip
    return m["accuracy"], m["localisation_accuracy"]


def fmt(s: tuple[float, float]) -> str:
    return f"{s[0]:.3f} / {s[1]:.3f}"


def estimate(pool_path: str) -> None:
    """Write the motion fit's placement for each test placement (arm data mixed by the truth)."""
    pool = load_checkpoint(pool_path)
    graph = graph_from_checkpoint(pool)
    reference = load_recordings(expand_paths(pool["config"]["data"]["train"]))
    (SELFCAL / "estimated").mkdir(parents=True, exist_ok=True)
    for seed in PLACEMENTS:
        truth = harness_graph(coupling_seed=seed, coupling_sensors=4).coupling
        c = motion_estimate(reference, healthy, replace(graph, coupling=truth), prune=0.0)
        (SELFCAL / "estimated" / f"seed{seed}.json").write_text(json.dumps(c.tolist()))


if sys.argv[1:2] == ["estimate"]:
    estimate(sys.argv[2])
    sys.exit(0)

print("# Self-calibration, then training on the placement found (retrofit, W = 32, seed 42)\n")
print(f"Made by `CORPUS={CORPUS} .venv/bin/python studies/stock_arm/self_calibration_retrain.py`.")
print("Accuracy / localisation, data mixed by the true placement: on the validation runs of the")
print("training sessions (where the choice of z-scores is made), then on the held-out session.\n")
print("| placement | corr(estimate, truth) | trained on the true placement: held-out | trained on "
      "the estimate, training's z-scores: validation | z-scored on the arm: validation | "
      "training's z-scores: held-out | z-scored on the arm: held-out |")  # fmt: skip
print("|---|---|---|---|---|---|---|")
rows = []
training = None
for seed in PLACEMENTS:
    truth = harness_graph(coupling_seed=seed, coupling_sensors=4).coupling
    estimate = np.array(json.loads((SELFCAL / "estimated" / f"seed{seed}.json").read_text()))
    ref = load_checkpoint(RUNS / f"seed{seed}_m4/anomaly_residual/w32/seed42/best.ckpt")
    retrained = load_checkpoint(SELFCAL / "retrained" / f"seed{seed}" / "best.ckpt")
    if training is None:
        training = load_recordings(expand_paths(retrained["config"]["data"]["train"]))
    row = (coupling_correlation(estimate, truth), score(ref, truth, False),
           score(retrained, truth, False, training), score(retrained, truth, True, training),
           score(retrained, truth, False), score(retrained, truth, True))  # fmt: skip
    rows.append(row)
    cells = " | ".join(fmt(r) for r in row[1:])
    print(f"| seed{seed}_m4 | {row[0]:.2f} | {cells} |", flush=True)
means = [np.mean([r[k] for r in rows], axis=0) for k in range(len(rows[0]))]
print(f"| mean | {means[0]:.2f} | " + " | ".join(fmt(m) for m in means[1:]) + " |")
