#!/usr/bin/env bash
# On-line alarms of the stock headline (stgnn_fixed, seed 42) on the three probe sessions: run by
# the nominal arm, by each unseen arm, and by each unseen arm after commissioning on ten minutes of
# its healthy running. Writes outputs/unseen_arms/monitor/*.json; studies/stock_arm/unseen_arms.py
# puts them in its table. Usage: bash studies/stock_arm/run_alarms.sh [CORPUS]
set -euo pipefail
C=${1:-outputs/corpus/standard}
S=outputs/thesis_physics/structural/stock/C0/stgnn_fixed/w32/seed42
M=outputs/unseen_arms/monitor
PY=.venv/bin/python
[ -f $S/model.onnx ] || $PY -m robohealth_mj.export ckpt=$S/best.ckpt data=$C/heldout_seed900
for arm in 910 911 912; do
  O=outputs/unseen_arms/onnx/arm$arm
  [ -f $O/model.onnx ] || $PY -m robohealth_mj.commission model=$S/best.ckpt \
    healthy=$C/healthy_unseen_arms_seed$arm out=$O
  for run in nominal:$S/model.onnx:probe_nominal_arms unseen:$S/model.onnx:probe_unseen_arms \
             commissioned:$O/model.onnx:probe_unseen_arms; do
    IFS=: read -r name model probe <<< "$run"
    [ -f $M/${name}_$arm.json ] || $PY -m robohealth_mj.monitor model=$model source=replay \
      file=$C/${probe}_seed$arm/graphs.jsonl evaluate=true quiet=true out=$M/${name}_$arm.json
  done
done
# False alarms on healthy running the commissioning never saw: 20 more minutes of each arm (the
# same drawn arm, arm.seed, on another program, seed), before and after commissioning.
GRID='curriculum.speed_scales=[0.6,1.0,1.5] curriculum.payload_scales=[0.5,1.0,1.6]'
for arm in 910 911 912; do
  H=$C/healthy_test_arm$arm
  [ -f $H/manifest.json ] && grep -q '"complete"' $H/manifest.json || $PY -m robohealth_mj.record \
    seed=$((arm + 10)) arm=varied arm.seed=$arm faults=none session.duration_s=1200 $GRID \
    session.progress=false session.out_dir=$H
  for run in healthy_before:$S/model.onnx healthy_after:outputs/unseen_arms/onnx/arm$arm/model.onnx; do
    IFS=: read -r name model <<< "$run"
    [ -f $M/${name}_$arm.json ] || $PY -m robohealth_mj.monitor model=$model source=replay \
      file=$H/graphs.jsonl evaluate=true quiet=true out=$M/${name}_$arm.json
  done
done
