#!/usr/bin/env bash
# The severity head (campaign issue, item 4): where its error comes from (results.md), for the
# severity block's three seeds and the loss-weight trials (weight 5: seed 42; weight 20: seeds 42-44).
set -euo pipefail
PY=${PY:-.venv/bin/python}
CORPUS=${CORPUS:-outputs/corpus/standard}
# The trials: the severity block with another loss weight, each weight its own root.
ROOT=outputs/severity_weight5 TRAIN_ARGS="seed=42 trainer.severity_loss_weight=5" \
  bash studies/thesis_physics/run.sh severity
ROOT=outputs/severity_weight20 TRAIN_ARGS="trainer.severity_loss_weight=20" \
  bash studies/thesis_physics/run.sh severity
run=structural/full/C0/anomaly_residual+severity/w32
$PY studies/thesis_physics/measure_severity.py "$CORPUS/heldout_seed900" \
  outputs/thesis_physics/$run/seed4{2,3,4}/best.ckpt outputs/severity_weight5/$run/seed42/best.ckpt \
  outputs/severity_weight20/$run/seed4{2,3,4}/best.ckpt > studies/thesis_physics/results/severity/results.md
