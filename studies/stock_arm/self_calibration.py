"""Placement self-calibration (stock-arm issue, item 4): a retrofit harness model commissioned on
ten healthy minutes of an arm whose sensors sit in a placement it never saw, against a model
trained on that placement. Retrofit sensing, W = 32, held-out session.

    CORPUS=outputs/corpus/standard .venv/bin/python studies/stock_arm/self_calibration.py \
        POOL_CKPT [SINGLE_CKPT] > studies/stock_arm/results/self_calibration.md

POOL_CKPT: trained with ``trainer.placements=256`` (command in studies/stock_arm/run.sh);
SINGLE_CKPT: the campaign's model trained on C0 alone (for contrast). Trained-on-placement
references: the campaign's runs of the pool model's seed under
``outputs/thesis_physics/harness/retrofit/<placement>``.
CORPUS (default ``outputs/corpus/standard``) holds the held-out session and ten healthy minutes
of the nominal arm (``healthy_nominal_seed940``, recorded by ``studies/stock_arm/run.sh``).
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.graphs import harness_graph
from robohealth_mj.deploy.commission import commission
from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checkpoint
from robohealth_mj.learn.evaluation import score_under_placement

CORPUS = os.environ.get("CORPUS", "outputs/corpus/standard")
RUNS = "outputs/thesis_physics/harness/retrofit"
HEALTHY = f"{CORPUS}/healthy_nominal_seed940"
PLACEMENTS = [2, 5, 21, 22, 23]  # seeds of 4-sensor placements; the pool's are 10000 and up
torch.set_num_threads(2)
held_all = load_recordings([f"{CORPUS}/heldout_seed900/graphs.jsonl"])
healthy = load_recordings([f"{HEALTHY}/graphs.jsonl"])


def acc_loc(m: dict) -> tuple[float, float]:
    return m["accuracy"], m["localisation_accuracy"]


def score(ckpt: dict) -> tuple[float, float]:
    """Accuracy and localisation on the held-out session, read through the checkpoint's graph."""
    return acc_loc(score_under_placement(ckpt, held_all))


def given(ckpt: dict, c: np.ndarray) -> tuple[float, float]:
    """The pool model told the placement: C set to it, sensors z-scored on its healthy run."""
    return acc_loc(score_under_placement(ckpt, held_all, c, healthy=healthy, tell_model=True))


def commissioned(path: str, seed: int, fit: str = "motion") -> tuple[tuple[float, float], float]:
    with tempfile.TemporaryDirectory() as out:
        record = commission(path, HEALTHY, out, export=False, placement={"coupling_seed": seed},
                            placement_fit=fit)  # fmt: skip
        ckpt = load_checkpoint(Path(out) / "best.ckpt")
    return score(ckpt), record["placement"]["coupling_correlation"]


def fmt(s: tuple[float, float]) -> str:
    return f"{s[0]:.3f} / {s[1]:.3f}"


pool_path = sys.argv[1]
single_path = sys.argv[2] if len(sys.argv) > 2 else None
pool = load_checkpoint(pool_path)
SEED = int(pool["config"]["seed"])  # the references: the campaign's runs of the pool's seed
print(f"# Placement self-calibration (retrofit harness, W = 32, seed {SEED}, held-out session)\n")
print(f"Made by `CORPUS={CORPUS} .venv/bin/python studies/stock_arm/self_calibration.py "
      f"{' '.join(sys.argv[1:])}`.")  # fmt: skip
print(
    "Accuracy / localisation. *Told it*: the pool model given the true placement. "
    "*Self-calibrated*: commissioned on ten healthy minutes (seed 940) with the placement "
    "hidden; commissioning also matches the healthy operating point, so its accuracy can "
    "differ from *told it*. corr: mean over joints of the row correlation with the truth.\n"
)
print("| placement | trained on it (acc. / loc.) | pool model, told it | pool model, "
      "self-calibrated: motion fit | corr(C, truth) | reconstruction fit | corr(C, truth) | "
      "C0-only model, motion fit |")  # fmt: skip
print("|---|---|---|---|---|---|---|---|")
c0 = graph_from_checkpoint(pool).coupling
c0_ref = load_checkpoint(f"{RUNS}/C0/anomaly_residual/w32/seed{SEED}/best.ckpt")
print(f"| C0 | {fmt(score(c0_ref))} "
      f"| {fmt(given(pool, c0))} | — | — | — | — | — |")  # fmt: skip
rows = []
for seed in PLACEMENTS:
    c = harness_graph(coupling_seed=seed, coupling_sensors=4).coupling
    ref_path = Path(f"{RUNS}/seed{seed}_m4/anomaly_residual/w32/seed{SEED}/best.ckpt")
    ref = score(load_checkpoint(ref_path)) if ref_path.is_file() else None
    motion, corr_m = commissioned(pool_path, seed)
    recon, corr_r = commissioned(pool_path, seed, "reconstruction")
    single = commissioned(single_path, seed)[0] if single_path else None
    told = given(pool, c)
    rows.append((ref, told, motion, corr_m, recon, corr_r))
    print(f"| seed{seed}_m4 | {fmt(ref) if ref else '—'} | {fmt(told)} | {fmt(motion)} | "
          f"{corr_m:.2f} | {fmt(recon)} | {corr_r:.2f} | {fmt(single) if single else '—'} |",
          flush=True)  # fmt: skip


def mean(k: int):
    return np.mean([r[k] for r in rows], axis=0)


refs = [r[0] for r in rows if r[0] is not None]
print(f"| mean of the {len(rows)} | {fmt(np.mean(refs, axis=0)) if refs else '—'} "
      f"({len(refs)} trained) | {fmt(mean(1))} | {fmt(mean(2))} | {mean(3):.2f} | "
      f"{fmt(mean(4))} | {mean(5):.2f} | — |")  # fmt: skip
