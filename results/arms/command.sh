#!/usr/bin/env bash
# Issue 36's cross-arm experiment, from the repository root (about 2.5 h on 2 cores for one seed
# of gbdt and stgnn_fixed; a lent GPU for the full three seeds with the headline variant):
#   1. each arm's corpus (conf/corpus/arms.yaml: eight training sessions, a held-out one, ten
#      healthy minutes to commission on, a healthy hour to count false alarms on);
#   2. per-arm models, then leave-one-arm-out (transfer=true on the three other arms), each
#      commissioned on the unseen arm and replayed over its healthy hour;
#   3. the table (results/arms/results.md).
# VARIANTS, SEEDS, EPOCHS, SENSING override the defaults below (this session's run).
set -euo pipefail
PY=${PY:-.venv/bin/python}
VARIANTS=${VARIANTS:-gbdt,stgnn_fixed}
SEEDS=${SEEDS:-42}
EPOCHS=${EPOCHS:-10}
SENSING=${SENSING:-full}
for arm in ur5e ur10e ur3e ur16e; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm \
    "record_overrides=[\"arm=$arm\"]" progress=false
done
$PY experiments/arms/campaign.py --variants "$VARIANTS" --seeds "$SEEDS" --epochs "$EPOCHS" \
  --sensing "$SENSING"
$PY experiments/arms/summarise.py --sensing "$SENSING" > "results/arms/table_$SENSING.md"
