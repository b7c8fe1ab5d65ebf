#!/usr/bin/env bash
# Issue 65, item 4, the stock profile: each seven-joint arm's own gbdt, mlp and stgnn_fixed, and
# the UR5e's beside them, on what the arm's controller reports (sensing=stock: position, velocity,
# effort, tracking error and torque residual per joint, no sensor package; the FR3, the iiwa
# and the Gen3 report their joint torque sensors as effort), W = 32, seeds 42-44, the networks
# at 10 epochs. With no sensor nodes there is no coupling head, so the headline
# (anomaly_residual) cannot read this profile: stgnn_fixed is its graph network, as in the UR
# arms' stock campaign. Reads the corpora run_seven.sh records; about 35 minutes on 2 cores.
#   bash studies/arms/run_stock_own.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
ARMS=${ARMS:-ur5e,fr3,iiwa14,gen3,xarm7}
C="$PY studies/arms/campaign.py --arms $ARMS --stages own --steps train --sensing stock"
C="$C --seeds ${SEEDS:-42,43,44} --out outputs/campaign_seven"
($C --variants gbdt --override model.severity=false && $C --variants mlp --epochs 10) &
$C --variants stgnn_fixed --epochs 10
wait
# OWN_TABLE= (empty): no table, for a runner that writes its own (run_stock_seeds.sh)
OWN_TABLE=${OWN_TABLE-seven_joint_own_stock}
[[ -z $OWN_TABLE ]] || $PY studies/arms/summarise.py --sensing stock --out outputs/campaign_seven \
  > studies/arms/results/$OWN_TABLE.md
