#!/usr/bin/env bash
# Issue 65, item 4, the stock profile left out at three seeds, from a fresh clone: each arm of
# ARMS (default the iiwa, the Gen3 and the xArm7) left out of the whole family (UR e-Series and
# the seven-joint arms) at seeds 42-44, beside its own stock models at the same seeds. Records what
# the runs read and no more: the training arms' training sessions (and held-out session), each
# left-out arm's whole corpus but the payload probe (its held-out session, validation sessions,
# ten healthy minutes and healthy hour). Tables: studies/arms/results/TABLES_{shift,as_trained}.md
# and validation_TABLES.md (TABLES defaults to family_stock_seeds; the CSVs are tagged seeds);
# about 20 minutes of corpus, 8 of own models and 30 of leave-one-arm-out an arm on 2 cores.
#   bash studies/arms/run_stock_seeds.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
ARMS=${ARMS:-iiwa14,gen3,xarm7}
FAMILY=ur5e,ur3e,ur10e,ur16e,ur20,ur30,fr3,iiwa14,gen3,xarm7
for arm in ${FAMILY//,/ }; do
  roles=('~corpus.probe_payload_high')
  [[ ,$ARMS, == *,$arm,* ]] ||
    roles+=('~corpus.validation' '~corpus.healthy_commissioning' '~corpus.healthy_hour')
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm progress=false \
    "record_overrides=[\"arm=$arm\"]" "${roles[@]}"
done
OWN_TABLE= ARMS=$ARMS SEEDS=42,43,44 PY=$PY bash studies/arms/run_stock_own.sh
TABLES=${TABLES:-family_stock_seeds} TAG=${TAG:-seeds} ARMS=$ARMS SEEDS=42,43,44 PY=$PY \
  bash studies/arms/run_stock_loao.sh
