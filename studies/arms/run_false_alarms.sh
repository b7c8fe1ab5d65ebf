#!/usr/bin/env bash
# Issue 65, 2026-12-06: where the iiwa's false alarms fall, and what quiets them. From the
# seven-joint leave-one-arm-out models of run_range.sh (seed 42, outputs/campaign_seven_limit):
# the iiwa's networks are commissioned on 30 healthy minutes (the ten of before and twenty more,
# seeds 941-942) at validation's operating point and at healthy_rate 0.99, each scored on the
# iiwa's held-out session and on its training sessions (validation: the recipe is chosen there),
# and their alarms counted over the healthy hour. Then the family's leave-one-arm-out after the
# mount and curriculum fixes (the six UR arms beside the other seven-joint arms), seed 42, and
# the same commissioning recipes on its iiwa, xArm7 and Gen3 models. About 40 minutes for the first
# part, 25 minutes an unseen arm for the second, on 2 cores. Tables: studies/arms/README.md,
# "The iiwa's false alarms, located" and "The whole family, after the fixes".
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
SEVEN=fr3,iiwa14,gen3,xarm7
$PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/iiwa14 progress=false \
  'record_overrides=["arm=iiwa14"]' '~corpus.probe_payload_high' \
  'corpus.healthy_commissioning.seeds=[940,941,942]'
L="$PY studies/arms/campaign.py --arms iiwa14 --family $SEVEN --stages loao --seeds 42 --out outputs/campaign_seven_limit --variants mlp,anomaly_residual --normalisation shift"
for minutes in 10 30; do
  $L --commissioning-minutes $minutes --steps commission,validate,alarms
  $L --commissioning-minutes $minutes --steps commission,validate,alarms --healthy-rate 0.99
done
R=outputs/campaign_seven_limit/full/loao/iiwa14/structural/full/C0
$PY studies/arms/false_alarms.py $R/{anomaly_residual,mlp}/w32/seed42/commissioned{,_hr0.99}_shift \
  > studies/arms/results/iiwa_false_alarms.md
$PY studies/arms/false_alarms.py --commissioning-minutes 30 \
  $R/{anomaly_residual,mlp}/w32/seed42/commissioned30{,_hr0.99}_shift \
  > studies/arms/results/iiwa_false_alarms_30min.md
for rate in "" 0.99; do
  for minutes in 10 30; do
    what=$([ -n "$rate" ] && echo "healthy rate $rate" || echo "validation's healthy rate")
    echo "## Commissioned on $minutes healthy minutes, at $what"
    echo
    $PY studies/arms/summarise.py --out outputs/campaign_seven_limit --own outputs/campaign_seven \
      --normalisation shift --commissioning-minutes $minutes ${rate:+--healthy-rate $rate}
  done
done > studies/arms/results/iiwa_commissioning_minutes.md
RECIPES=commissioned_shift,commissioned_hr0.99_shift,commissioned30_shift,commissioned30_hr0.99_shift
$PY studies/arms/normalisation.py --out outputs/campaign_seven_limit --recipes $RECIPES \
  --recall struct_weaken > studies/arms/results/iiwa_commissioning_recipes.md
# The whole family (UR e-Series and seven-joint arms) left out one seven-joint arm at a time,
# after the mount and curriculum fixes: the UR arms other than the UR5e bring two training
# sessions each, as in run_seven.sh
$PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/ur5e progress=false \
  'record_overrides=["arm=ur5e"]' '~corpus.probe_payload_high' '~corpus.healthy_hour'
for arm in ur3e ur10e ur16e ur20 ur30; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm progress=false \
    corpus.train.sessions=2 "record_overrides=[\"arm=$arm\"]" '~corpus.probe_payload_high' \
    '~corpus.healthy_hour' '~corpus.healthy_commissioning' '~corpus.validation'
done
for arm in ${FAMILY_ARMS:-iiwa14 xarm7 fr3 gen3}; do
  PY=$PY bash studies/arms/loao_one_arm.sh $arm ur5e,ur3e,ur10e,ur16e,ur20,ur30,$SEVEN \
    outputs/campaign_family_fixed
done
# the family's iiwa, xArm7 and Gen3 networks commissioned on 30 minutes as well, at validation's rate
# and at 0.99, each scored on validation (the arm's training sessions)
for arm in xarm7 gen3; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm progress=false \
    "record_overrides=[\"arm=$arm\"]" '~corpus.probe_payload_high' \
    'corpus.healthy_commissioning.seeds=[940,941,942]'
done
for arm in iiwa14 xarm7 gen3; do
  F="$PY studies/arms/campaign.py --arms $arm --family ur5e,ur3e,ur10e,ur16e,ur20,ur30,$SEVEN --stages loao --seeds 42 --out outputs/campaign_family_fixed --variants mlp,anomaly_residual --normalisation shift"
  $F --commissioning-minutes 30 --steps commission,alarms,validate
  $F --commissioning-minutes 30 --steps commission,alarms,validate --healthy-rate 0.99
  $F --steps validate
done
$PY studies/arms/normalisation.py --out outputs/campaign_family_fixed \
  --recipes commissioned_shift,commissioned30_shift,commissioned30_hr0.99_shift \
  --recall struct_weaken > studies/arms/results/family_fixed_recipes.md
$PY studies/arms/summarise.py --out outputs/campaign_family_fixed --own outputs/campaign_seven \
  --normalisation shift > studies/arms/results/family_fixed_shift.md
$PY studies/arms/summarise.py --out outputs/campaign_family_fixed --own outputs/campaign_seven \
  > studies/arms/results/family_fixed.md
