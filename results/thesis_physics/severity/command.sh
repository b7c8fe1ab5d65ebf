#!/usr/bin/env bash
# The severity head (campaign issue, item 4): where its error comes from (results.md), for the
# severity block's three seeds and the two loss-weight trials (seed 42; weights 5 and 20).
set -euo pipefail
PY=${PY:-.venv/bin/python}
CORPUS=${CORPUS:-outputs/corpus/standard}
for w in 5 20; do  # the trials: the severity block with another loss weight, each its own root
  JOBS=1 ROOT=outputs/severity_weight$w TRAIN_ARGS="seed=42 trainer.severity_loss_weight=$w" \
    bash results/thesis_physics/command.sh severity
done
run=structural/full/C0/anomaly_residual+severity/w32
$PY results/thesis_physics/severity/measure.py "$CORPUS/heldout_seed900" \
  outputs/thesis_physics/$run/seed4{2,3,4}/best.ckpt \
  outputs/severity_weight{5,20}/$run/seed42/best.ckpt > results/thesis_physics/severity/results.md
