#!/usr/bin/env bash
# Issue 65, item 4, the stock profile left out: each arm of ARMS (default the FR3) left out of
# the whole family's training (UR e-Series and the seven-joint arms), read on what its
# controller reports (sensing=stock), W = 32, at SEEDS (default 42). gbdt, mlp and stgnn_fixed,
# the graph network this profile can have (no sensor nodes, so no coupling head and no
# headline); commissioned as on the full profile (gbdt: none; the networks: shift), then every
# recipe scored on the arm's validation sessions (programs no arm trains on) to pick one; the
# networks as trained are exported and their alarms counted too (validate_one_arm.sh).
# NETWORK=gat (or another graph variant that reads joint nodes only) trains that network in
# stgnn_fixed's place; the finished gbdt and mlp runs are skipped.
# Reads the corpora run_seven.sh and run_validation.sh record and the own stock models
# run_stock_own.sh trains; about 10 minutes an arm at one seed on 2 cores, 25 at two. The tables
# go to studies/arms/results/TABLES_{shift,as_trained}.md and validation_TABLES.md (TABLES
# defaults to family_stock), and the CSVs to results_campaign_family_fixed_[TAG_]*_stock.csv.
#   bash studies/arms/run_stock_loao.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
ARMS=${ARMS:-fr3}
SEEDS=${SEEDS:-42}
FAMILY=ur5e,ur3e,ur10e,ur16e,ur20,ur30,fr3,iiwa14,gen3,xarm7
OUT=outputs/campaign_family_fixed
TABLES=${TABLES:-family_stock}
NET=${NETWORK:-stgnn_fixed}
for arm in ${ARMS//,/ }; do
  for step in loao_one_arm validate_one_arm; do
    SENSING=stock NETWORK=$NET SEEDS=$SEEDS PY=$PY \
      bash studies/arms/$step.sh "$arm" $FAMILY $OUT
  done
done
S="$PY studies/arms/summarise.py --sensing stock --out $OUT --own outputs/campaign_seven"
S="$S${TAG:+ --tag $TAG}"
$S --normalisation shift --baseline-normalisation none > studies/arms/results/${TABLES}_shift.md
$S --as-trained > studies/arms/results/${TABLES}_as_trained.md
$PY studies/arms/validation_sessions.py --out $OUT --sensing stock \
  --recipes uncommissioned,commissioned,commissioned_shift \
  > studies/arms/results/validation_${TABLES}.md
