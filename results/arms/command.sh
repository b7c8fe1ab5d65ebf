#!/usr/bin/env bash
# Issue 36's cross-arm experiment as run on 2026-11-25, from the repository root (about two hours
# on 2 cores; a lent GPU for the full campaign: SEEDS=42,43,44 for the own models too,
# VARIANTS=gbdt,stgnn_fixed,anomaly_residual, EPOCHS=30, SENSING=stock as well):
#   1. each arm's corpus (conf/corpus/arms.yaml: eight training sessions, a held-out one, ten
#      healthy minutes to commission on, a healthy hour to count false alarms on);
#   2. per-arm models (seed 42), then leave-one-arm-out (transfer=true on the three other arms,
#      seeds 42-44), each commissioned on the unseen arm and replayed over its healthy hour;
#   3. the relative-channel ablation and the more-epochs candidate (seed 42);
#   4. the tables (results/arms/table_full.md, raw_channels.md) and the recorder per arm.
set -euo pipefail
PY=${PY:-.venv/bin/python}
VARIANTS=${VARIANTS:-gbdt,stgnn_fixed}
EPOCHS=${EPOCHS:-10}
SENSING=${SENSING:-full}
for arm in ur5e ur10e ur3e ur16e; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm \
    "record_overrides=[\"arm=$arm\"]" progress=false
done
$PY experiments/arms/campaign.py --variants "$VARIANTS" --seeds "${SEEDS:-42}" --epochs "$EPOCHS" \
  --sensing "$SENSING"
$PY experiments/arms/campaign.py --variants "$VARIANTS" --seeds "${LOAO_SEEDS:-43,44}" \
  --epochs "$EPOCHS" --sensing "$SENSING" --stages loao
$PY experiments/arms/raw_channels.py --arms ur3e,ur16e > results/arms/raw_channels.md
$PY experiments/arms/campaign.py --variants stgnn_fixed --stages loao --epochs 30 --arms ur3e \
  --out outputs/campaign_arms_e30
$PY experiments/arms/summarise.py --sensing "$SENSING" > "results/arms/table_$SENSING.md"
$PY experiments/arms/summarise.py --out outputs/campaign_arms_e30 > results/arms/table_e30.md
$PY -m robohealth_mj.bench sim --duration 120 --arms ur5e,ur3e,ur10e,ur16e \
  > results/arms/bench_sim.txt
