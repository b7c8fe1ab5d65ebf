#!/usr/bin/env bash
# After loao_one_arm.sh: every recipe of ARM's left-out models scored on its validation sessions
# (gbdt as trained and commissioned; the networks as trained and commissioned with shift), so
# that validation picks one, and the networks as trained exported with their alarms counted over
# ARM's healthy hour (validation may pick them). Takes loao_one_arm.sh's SEEDS, SENSING, NETWORK
# and UNSEEN_SESSIONS; what is done is skipped. Used by run_stock_loao.sh and
# run_unseen_sessions.sh.
#   bash studies/arms/validate_one_arm.sh ARM FAMILY OUT
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
arm=$1 family=$2 out=$3
V="$PY studies/arms/campaign.py --arms $arm --family $family --stages loao --out $out"
V="$V --seeds ${SEEDS:-42} --unseen-sessions ${UNSEEN_SESSIONS:-0} --sensing ${SENSING:-full}"
NETS=mlp,${NETWORK:-anomaly_residual}
$V --variants gbdt --steps validate
$V --variants $NETS --normalisation shift --steps validate
$V --variants $NETS --normalisation shift --steps export,alarms
