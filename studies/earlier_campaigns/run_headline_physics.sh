#!/usr/bin/env bash
# The fault-visibility issue's rows on the standard corpus recorded with fault_model=physics (the
# default since schema 2.0), W = 32, seeds 42-44, two lanes of one thread each: gbdt and the
# headline anomaly_residual (30 epochs without early stopping: at 20 epochs its validation score
# was still rising at the last epoch, and early stopping cuts the one-cycle schedule before its
# low-rate end), the gbdt channel ablation, the 20-epoch headline and the harness rows (seed 42);
# then the report and the ONNX
# export. Run from the repository root; about 80 min on 2 cores.
set -euo pipefail
PY=${PY:-.venv/bin/python}
$PY -m robohealth_mj.corpus                      # outputs/corpus/standard (physics), ~9 min
C="+experiment=headline hydra.sweep.dir=outputs/campaign_physics threads=1 trainer.progress=false"
T="threads=1 trainer.progress=false"
(
  $PY -m robohealth_mj.train -m $C variant=gbdt seed=42,43,44
  $PY -m robohealth_mj.train variant=gbdt seed=42 $T out_dir=outputs/ablation_physics/gbdt_v1_channels \
    'model.channels=[pos,vel,effort,vib,acc_x,acc_y,acc_z]'
  $PY -m robohealth_mj.train variant=gbdt seed=42 $T out_dir=outputs/ablation_physics/gbdt_v1_plus_joint \
    'model.channels=[pos,vel,effort,pos_error,effort_residual,vib,acc_x,acc_y,acc_z]'
  $PY -m robohealth_mj.train -m $C graph=harness variant=gbdt seed=42
  for s in 42 43 44; do
    $PY -m robohealth_mj.train variant=anomaly_residual seed=$s $T out_dir=outputs/ablation_physics/anomaly_e20_seed$s
  done
) &
$PY -m robohealth_mj.train -m $C trainer.epochs=30 trainer.patience=30 variant=anomaly_residual seed=42,43,44
$PY -m robohealth_mj.train -m $C trainer.epochs=30 trainer.patience=30 variant=anomaly_residual seed=42 graph=harness
wait
$PY -m robohealth_mj.report outputs/campaign_physics
cp outputs/campaign_physics/report/* studies/earlier_campaigns/results/headline_physics/
$PY -m robohealth_mj.export ckpt=outputs/campaign_physics/structural/anomaly_residual/w32/seed42/best.ckpt \
  out=studies/earlier_campaigns/results/headline_physics/anomaly_residual_w32_seed42.onnx
