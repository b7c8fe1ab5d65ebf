"""Choosing the pool model's design for placement self-calibration, on validation placements.

A pool model (``trainer.placements``) is scored on the validation runs of its training sessions
(never the held-out session) with their sensors mixed by five placements drawn for this choice
alone (seeds 31-35: neither the pool's nor the five test placements of
``self_calibration.py``), twice: *told* the placement, and *self-calibrated* (commissioned on
the nominal arm's ten healthy minutes with the placement hidden, the rest frozen), with the
motion fit plain and pruned (``recouple.PRUNE``, also chosen on these placements). The held-out
column (the five test placements, told) is printed for the record, after the choice.

    CORPUS=outputs/corpus/standard .venv/bin/python studies/stock_arm/pool_design.py \
        NAME=POOL_CKPT [NAME=POOL_CKPT ...] > studies/stock_arm/results/pool_design.md
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

from robohealth_mj.data.arrays import Recording, expand_paths, load_recordings
from robohealth_mj.data.graphs import harness_graph
from robohealth_mj.deploy import recouple
from robohealth_mj.deploy.commission import commission
from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checkpoint
from robohealth_mj.learn.evaluation import score_under_placement

CORPUS = os.environ.get("CORPUS", "outputs/corpus/standard")
HEALTHY = f"{CORPUS}/healthy_nominal_seed940"
VALIDATION_PLACEMENTS = [31, 32, 33, 34, 35]
TEST_PLACEMENTS = [2, 5, 21, 22, 23]
torch.set_num_threads(int(os.environ.get("THREADS", "1")))
healthy = load_recordings([f"{HEALTHY}/graphs.jsonl"])
held = load_recordings([f"{CORPUS}/heldout_seed900/graphs.jsonl"])


def acc_loc(m: dict) -> np.ndarray:
    return np.array([m["accuracy"], m["localisation_accuracy"]])


def score(ckpt: dict, c: np.ndarray, data: Recording, val_only: bool) -> np.ndarray:
    """Accuracy and localisation of ``ckpt`` told placement ``c`` (its sensors z-scored on the
    arm's healthy running) on ``data`` mixed by ``c``; ``val_only``: its validation runs."""
    return acc_loc(score_under_placement(ckpt, data, c, healthy=healthy, tell_model=True,
                                         validation_only=val_only))  # fmt: skip


def self_calibrated(
    path: str, seed: int, data: Recording, prune: float
) -> tuple[np.ndarray, float]:
    """Commission ``path`` on the arm mixed by placement ``seed`` (hidden), the motion fit
    pruned at ``prune``, then score it."""
    with tempfile.TemporaryDirectory() as out:
        record = commission(path, HEALTHY, out, export=False, placement={"coupling_seed": seed},
                            placement_prune=prune)  # fmt: skip
        ckpt = load_checkpoint(Path(out) / "best.ckpt")
    truth = harness_graph(coupling_seed=seed, coupling_sensors=4).coupling
    # the arm mixes by the truth; the model reads it through the C it was fitted
    m = score_under_placement(ckpt, data, truth, validation_only=True)
    return acc_loc(m), record["placement"]["coupling_correlation"]


def fmt(s: np.ndarray) -> str:
    return f"{s[0]:.3f} / {s[1]:.3f}"


designs = [a.split("=", 1) for a in sys.argv[1:]]
training = load_recordings(expand_paths(load_checkpoint(designs[0][1])["config"]["data"]["train"]))
print("# The pool model's design, chosen on validation placements (retrofit, W = 32, seed 42)\n")
print(f"Made by `CORPUS={CORPUS} .venv/bin/python studies/stock_arm/pool_design.py "
      f"{' '.join(sys.argv[1:])}`.")  # fmt: skip
print(
    "Accuracy / localisation. Validation: the training sessions' validation runs mixed by "
    f"placements {VALIDATION_PLACEMENTS} (mean of 5; the choice is made on these). Held-out: "
    f"the held-out session mixed by the test placements {TEST_PLACEMENTS}, told (mean of 5; "
    "read after the choice).\n"
)
print("| design | validation, C0 told | validation, told | self-calibrated, plain fit | corr(C, "
      "truth) | self-calibrated, pruned fit | corr(C, truth) | held-out, told |")  # fmt: skip
print("|---|---|---|---|---|---|---|---|")
for name, path in designs:
    ckpt = load_checkpoint(path)
    c0 = score(ckpt, np.asarray(graph_from_checkpoint(ckpt).coupling), training, True)
    told, plain, pruned = [], [], []
    for seed in VALIDATION_PLACEMENTS:
        c = harness_graph(coupling_seed=seed, coupling_sensors=4).coupling
        told.append(score(ckpt, c, training, True))
        plain.append(self_calibrated(path, seed, training, 0.0))
        pruned.append(self_calibrated(path, seed, training, recouple.PRUNE))
    test = [score(ckpt, harness_graph(coupling_seed=s, coupling_sensors=4).coupling, held, False)
            for s in TEST_PLACEMENTS]  # fmt: skip
    cells = [f"{fmt(np.mean([s for s, _ in fits], 0))} | {np.mean([r for _, r in fits]):.2f}"
             for fits in (plain, pruned)]  # fmt: skip
    print(
        f"| {name} | {fmt(c0)} | {fmt(np.mean(told, 0))} | {' | '.join(cells)} | "
        f"{fmt(np.mean(test, 0))} |",
        flush=True,
    )
