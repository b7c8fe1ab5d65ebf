#!/usr/bin/env bash
# One unseen arm's leave-one-arm-out at seed 42 (or at the seeds SEEDS names, e.g. SEEDS=43,44):
# gbdt, mlp and the headline trained on the other arms of FAMILY (two jobs of one thread), scored
# on ARM's held-out session, then commissioned by validation's recipe (gbdt: none; the networks:
# shift) on its ten healthy minutes, and the networks' alarms counted over its healthy hour. Used
# by run_range.sh, run_false_alarms.sh, run_family_seeds.sh and run_unseen_sessions.sh (which
# adds the first UNSEEN_SESSIONS of ARM's training sessions to the family's). SENSING=stock with
# NETWORK=stgnn_fixed runs the stock profile (no sensor nodes, so no coupling head: the headline
# cannot read it).
#   bash studies/arms/loao_one_arm.sh ARM FAMILY OUT
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
arm=$1 family=$2 out=$3
L="$PY studies/arms/campaign.py --arms $arm --family $family --stages loao --out $out"
L="$L --seeds ${SEEDS:-42} --unseen-sessions ${UNSEEN_SESSIONS:-0} --sensing ${SENSING:-full}"
NET=${NETWORK:-anomaly_residual}
($L --variants gbdt --override model.severity=false --steps train,rescore,commission &&
  $L --variants mlp --epochs 10 --steps train,rescore) &
$L --variants $NET --epochs 10 --steps train,rescore
wait
$L --variants mlp,$NET --steps commission,alarms --normalisation shift
