#!/usr/bin/env bash
# Issue 65, item 4: each seven-joint arm's own models beside the UR5e's, the UR5e's models read
# on each seven-joint arm, and leave-one-arm-out over the four seven-joint arms (trained on the
# other three, read by place along the chain), before and after commissioning, with false alarms
# over the unseen arm's healthy hour; from a fresh clone, about four hours on 2 cores.
# Each arm's corpus is conf/corpus/arms.yaml without the probe (the quick corpus's eight training
# sessions and held-out session, ten healthy minutes to commission on, a healthy hour);
# W = 32, seed 42 (leave-one-arm-out: seeds 42-44; LOAO_SEEDS=42 for one, about two hours less),
# the networks at 10 epochs, one thread each, two at a time. The tables:
# studies/arms/results/seven_joint_own.md and seven_joint_loao.md. Leave-one-arm-out with the
# six-joint UR arms among the training arms is not in it: see studies/arms/README.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
ARMS=${ARMS:-ur5e,fr3,iiwa14,gen3,xarm7}
for arm in ${ARMS//,/ }; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm progress=false \
    "record_overrides=[\"arm=$arm\"]" '~corpus.probe_payload_high'
done
C="$PY studies/arms/campaign.py --arms $ARMS --stages own --steps train --seeds 42 --out outputs/campaign_seven"
($C --variants gbdt --override model.severity=false && $C --variants mlp --epochs 10) &
$C --variants anomaly_residual --epochs 10
wait
# Leave-one-arm-out over the seven-joint arms: each trained on the other three (transfer=true),
# scored on the unseen arm, commissioned on its ten healthy minutes, scored again, and the
# networks' alarms counted over its healthy hour.
SEVEN=fr3,iiwa14,gen3,xarm7
LS=${LOAO_SEEDS:-42,43,44}
L="$PY studies/arms/campaign.py --arms $SEVEN --stages loao --seeds $LS --out outputs/campaign_seven"
($L --variants gbdt --override model.severity=false && $L --variants mlp --epochs 10) &
$L --variants anomaly_residual --epochs 10
wait
# The commissioning's normalisation (none, shift, moments), chosen on the unseen arm's training
# sessions (validation), and the headline without its per-place node embedding; where each unseen
# arm's healthy running sits against its training arms' (results/healthy_offsets.md).
for m in shift moments; do
  $L --variants gbdt,mlp,anomaly_residual --steps commission,validate --normalisation $m
done
$L --variants gbdt,mlp,anomaly_residual --steps validate
N="${L/campaign_seven/campaign_seven_noemb} --variants anomaly_residual --epochs 10"
$N --steps train --override model.backbone.node_embedding=false
$N --steps commission,validate,alarms
$PY studies/arms/normalisation.py --out outputs/campaign_seven > studies/arms/results/normalisation.md
$PY studies/arms/healthy_offsets.py --campaign outputs/campaign_seven > studies/arms/results/healthy_offsets.md
# Leave-one-arm-out over the whole family: the six UR e-Series arms beside the three other
# seven-joint arms, across joint counts (transfer=true places a UR's six joints on seven places:
# docs/training.md). To fit 2 cores, the UR arms other than the UR5e bring two training
# sessions each (the UR5e its eight): 42 sessions per model.
for arm in ur3e ur10e ur16e ur20 ur30; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm progress=false \
    corpus.train.sessions=2 "record_overrides=[\"arm=$arm\"]" '~corpus.probe_payload_high' \
    '~corpus.healthy_hour' '~corpus.healthy_commissioning' '~corpus.validation'
done
F="$L --family ur5e,ur3e,ur10e,ur16e,ur20,ur30,$SEVEN"
F="${F/campaign_seven/campaign_family}"
F="${F/--seeds $LS/--seeds 42}"  # the family at one seed (2.5 h)
($F --variants gbdt --override model.severity=false && $F --variants mlp --epochs 10) &
$F --variants anomaly_residual --epochs 10
wait
# The ablation: the FR3 read from its motors' currents (sensors.joint_torque=false) instead of its
# joint torque sensors, which see the link side of the drive and so not the drive's friction.
$PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/fr3_current progress=false \
  'record_overrides=["arm=fr3","sensors.joint_torque=false"]' '~corpus.healthy_hour' \
  '~corpus.probe_payload_high'
D="$PY studies/arms/campaign.py --arms fr3_current --stages own --steps train --seeds 42 --out outputs/campaign_seven"
($D --variants gbdt --override model.severity=false) &
$D --variants anomaly_residual --epochs 10
wait
$PY studies/arms/summarise.py --out outputs/campaign_seven
$PY studies/arms/summarise.py --out outputs/campaign_family --own outputs/campaign_seven \
  --against outputs/campaign_seven
$PY studies/arms/six_to_seven.py
$PY studies/arms/tracking_and_speed.py
# A mixed fleet: the UR5e's and the FR3's own headline models in one process (results/mixed_fleet.md)
RUN=structural/full/C0/anomaly_residual/w32/seed42
for arm in ur5e fr3; do
  $PY -m robohealth_mj.export ckpt=outputs/campaign_seven/full/own/$arm/$RUN/best.ckpt
done
$PY -m robohealth_mj.bench mixed --streams 500 --ticks 100 --rounds 3 \
  --model outputs/campaign_seven/full/own/{ur5e,fr3}/$RUN/model.onnx \
  --data outputs/corpus/arms/{ur5e,fr3}/heldout_seed900
