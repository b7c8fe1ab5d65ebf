#!/usr/bin/env bash
# Issue 65: the two arms whose family leave-one-arm-out missed "within 3 points of the arm's own
# model" at seed 42 (the FR3 and the xArm7), at seeds 43 and 44 too, and every arm's own model at
# seeds 42-44 on the recordings the family read, so that each gap and the graph-against-gbdt
# comparison carry a three-seed spread. Reads the corpora run_false_alarms.sh records; about
# 100 minutes on 2 cores (own models about 40 of them). ARMS=iiwa14,gen3 does the same for the
# other two seven-joint arms (about 40 minutes each; what is done is skipped). Last, where each
# arm's gap comes from, class by class (class_gaps.py).
#   bash studies/arms/run_family_seeds.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
ARMS=${ARMS:-fr3,xarm7}
FAMILY=ur5e,ur3e,ur10e,ur16e,ur20,ur30,fr3,iiwa14,gen3,xarm7
C="$PY studies/arms/campaign.py --arms ur5e,fr3,iiwa14,gen3,xarm7 --stages own --steps train"
C="$C --seeds 42,43,44 --out outputs/campaign_seven"
($C --variants gbdt --override model.severity=false && $C --variants mlp --epochs 10) &
$C --variants anomaly_residual --epochs 10
wait
for arm in ${ARMS//,/ }; do
  SEEDS=43,44 PY=$PY bash studies/arms/loao_one_arm.sh $arm $FAMILY outputs/campaign_family_fixed
done
$PY studies/arms/summarise.py --out outputs/campaign_family_fixed --own outputs/campaign_seven \
  --normalisation shift --baseline-normalisation none > studies/arms/results/family_seeds_shift.md
$PY studies/arms/summarise.py --out outputs/campaign_family_fixed --own outputs/campaign_seven \
  > studies/arms/results/family_seeds.md
# The xArm7's models at seeds 43 and 44 on thirty commissioning minutes too, and every model
# scored on the arm's training sessions (validation), to see whether the longer commissioning
# closes its gap; the iiwa's and the Gen3's (which raise false alarms on ten minutes at seed 42)
# on thirty minutes at healthy_rate=0.99 as well, the quieter operating point.
for arm in xarm7 iiwa14 gen3; do
  [[ $arm == xarm7 || ,$ARMS, == *,$arm,* ]] || continue
  F="$PY studies/arms/campaign.py --arms $arm --family $FAMILY --stages loao --seeds 43,44"
  F="$F --out outputs/campaign_family_fixed --variants mlp,anomaly_residual --normalisation shift"
  $F --commissioning-minutes 30 --steps commission,alarms,validate
  [[ $arm == xarm7 ]] ||
    $F --commissioning-minutes 30 --healthy-rate 0.99 --steps commission,alarms,validate
  $F --steps validate
done
S="$PY studies/arms/summarise.py --out outputs/campaign_family_fixed --own outputs/campaign_seven"
$S --normalisation shift --commissioning-minutes 30 > studies/arms/results/family_seeds_30min_shift.md
$S --normalisation shift --commissioning-minutes 30 --healthy-rate 0.99 \
  > studies/arms/results/family_seeds_30min_hr0.99_shift.md
$PY studies/arms/class_gaps.py --arms fr3,xarm7,iiwa14,gen3 > studies/arms/results/class_gaps.md
# each seed's recipes side by side on validation (the unseen arm's training sessions), held-out
# and false alarms, for the arms commissioned on thirty minutes
for seed in 42 43 44; do
  $PY studies/arms/normalisation.py --out outputs/campaign_family_fixed --seed $seed \
    --recipes commissioned_shift,commissioned30_shift,commissioned30_hr0.99_shift \
    > studies/arms/results/family_seeds_recipes_seed$seed.md
done
