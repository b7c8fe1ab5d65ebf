#!/usr/bin/env bash
# Issue 65, 2026-12-06: the leave-one-arm-out picks made again on validation sessions whose
# programs no arm trains on (README, "Validation on programmes no arm trains on"). Records each
# seven-joint arm's two validation sessions (conf/corpus/arms.yaml, role validation; the corpus
# skips what is recorded), moves the old scores on the arm's training sessions aside as
# eval_validation_shared_programme.json, scores every family leave-one-arm-out model
# (run_family_seeds.sh) and two-own-sessions model (run_unseen_sessions.sh) there, and writes the
# tables. About 50 minutes on 2 cores, beside another campaign.
#   bash studies/arms/run_validation.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
FAMILY=ur5e,ur3e,ur10e,ur16e,ur20,ur30,fr3,iiwa14,gen3,xarm7
for arm in iiwa14 fr3 xarm7 gen3; do
  minutes='corpus.healthy_commissioning.seeds=[940,941,942]'
  [[ $arm == fr3 ]] && minutes='corpus.healthy_commissioning.seeds=[940]'
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm progress=false jobs=1 \
    "record_overrides=[\"arm=$arm\"]" '~corpus.probe_payload_high' "$minutes"
done
# scores on the arm's training sessions, from before the validation sessions were recorded
for old in $(find outputs/campaign_family_fixed outputs/campaign_family_plus2 \
  -name eval_validation.json -exec grep -l '/train_0' {} +); do
  mv "$old" "${old%.json}_shared_programme.json"
done
for arm in fr3 xarm7 iiwa14; do
  V="$PY studies/arms/campaign.py --arms $arm --family $FAMILY --stages loao --seeds 42,43,44"
  V="$V --out outputs/campaign_family_plus2 --unseen-sessions 2 --steps validate"
  $V --variants gbdt
  $V --variants mlp,anomaly_residual --normalisation shift
done
for arm in fr3 xarm7 iiwa14 gen3; do
  F="$PY studies/arms/campaign.py --arms $arm --family $FAMILY --stages loao --seeds 42,43,44"
  F="$F --out outputs/campaign_family_fixed --steps validate"
  $F --variants gbdt
  $F --variants mlp,anomaly_residual --normalisation shift
  [[ $arm == fr3 ]] && continue  # the FR3 was commissioned on ten minutes only
  $F --variants mlp,anomaly_residual --normalisation shift --commissioning-minutes 30
  $F --variants mlp,anomaly_residual --normalisation shift --commissioning-minutes 30 \
    --healthy-rate 0.99
done
S="$PY studies/arms/validation_sessions.py"
$S > studies/arms/results/validation_plus2.md
$S --out outputs/campaign_family_fixed \
  --recipes uncommissioned,commissioned,commissioned_shift,commissioned30_shift,commissioned30_hr0.99_shift \
  > studies/arms/results/validation_family_fixed.md
