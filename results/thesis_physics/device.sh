#!/usr/bin/env bash
# The campaign on a lent GPU machine (16 cores, one GPU; the device tool's README), after
# `command.sh corpus` has recorded the standard corpus there (one session per core): the structural blocks,
# the neural variants on the GPU (12 runs side by side), gbdt on 3 cores. The missing Python
# packages travel as .site/ (PYTHONPATH). Harness, placement and severity blocks: command.sh on CPU.
set -euo pipefail
export PY=${PY:-python3} ROOT=${ROOT:-outputs/thesis_physics}
C=results/thesis_physics/command.sh
gpu() { TRAIN_ARGS="trainer.device=${DEVICE:-cuda} variant=$1" JOBS=${GPU_JOBS:-12} bash $C "${@:2}"; }
(
  gpu mlp,gat,stgnn_fixed,stgnn_fixed_pose,stgnn_learnable,stgnn_pose_cond,stgnn_pose_spectral,anomaly_residual,pose_anomaly matrix
  gpu mlp,gat,stgnn_fixed,stgnn_pose_cond,anomaly_residual,pose_anomaly matrix_w32
  gpu stgnn_pose_cond,anomaly_residual windows
) >"$ROOT.gpu.log" 2>&1 &
(TRAIN_ARGS="variant=gbdt" JOBS=3 bash $C matrix matrix_w32 windows) >"$ROOT.cpu.log" 2>&1 &
wait
