#!/usr/bin/env bash
# Issue 38, item 4: the fleet step on the CUDA execution provider, beside the CPU provider on the
# same machine, as run on 2026-11-26 on a lent machine (one NVIDIA H200, 16 CPU cores; image with
# CUDA 13 and torch 2.11+cu130). onnxruntime-gpu 1.31.1 is the CUDA 13 build (its CUDA provider
# needs libcublas.so.13, libcudart.so.13, libcurand.so.10: the image's nvidia-* wheels, which
# FleetRuntime loads through onnxruntime.preload_dlls()). The replay is the first 2,400 snapshots
# of the standard held-out session (outputs/corpus/standard/heldout_seed900). From the repository
# root, with onnxruntime-gpu installed in place of onnxruntime:
set -euo pipefail
PY=${PY:-python3}
M=studies/earlier_campaigns/results/headline_physics/anomaly_residual_w32_seed42.onnx
mkdir -p outputs/replay2400
head -n 2400 outputs/corpus/standard/heldout_seed900/graphs.jsonl > outputs/replay2400/graphs.jsonl
D=outputs/replay2400/graphs.jsonl
CUDA=CUDAExecutionProvider,CPUExecutionProvider
B="$PY -m robohealth_mj.bench streams --model $M --data $D"
# where a tick's time goes: CUDA (parts of 256 and of 8192 streams), then the CPU provider
{
  $B --profile-ticks 50 --providers $CUDA --shards 2 --chunk 256 --profile 1000 4000 8000
  $B --profile-ticks 50 --providers $CUDA --shards 2 --chunk 8192 --profile 1000 4000 8000 16000
  $B --profile-ticks 50 --providers CPUExecutionProvider --shards 2 --chunk 256 --profile 1000 4000
  $B --profile-ticks 50 --providers CPUExecutionProvider --shards 16 --chunk 256 --profile 4000 16000
} > studies/fleet/results/cuda/profile_cuda_vs_cpu.txt
# sustained streams (search), a paced run and the windowed path, on CUDA
for chunk in 8192 256; do
  $B --providers $CUDA --shards 2 --chunk $chunk --limit 16384 --seconds 20 --streams 4000 \
    --memory-rounds 1
done > studies/fleet/results/cuda/streams_cuda.txt
# the CPU provider on the same machine: the search (from 2,000) and a paced run at 3,000
$PY -c "
from robohealth_mj.benchmarks.fleet import _frames
from robohealth_mj.benchmarks.streams import search
n, _ = search('$M', _frames(['$D']), 100, start=2000, shards=2, chunk=256,
              providers=['CPUExecutionProvider'])
print('CPU EP sustained', n)" > studies/fleet/results/cuda/streams_cpu_same_machine.txt
$B --providers CPUExecutionProvider --shards 2 --chunk 256 --no-search --seconds 10 \
  --streams 3000 --memory-rounds 0 >> studies/fleet/results/cuda/streams_cpu_same_machine.txt
# the networks train on CUDA: the tests' learnable corpus (tests/conftest.py, LEARNABLE), 3 epochs
LEARNABLE="faults.schedule.fault_s=3.0 faults.schedule.healthy_s=1.5 faults.schedule.severities=[0.9]
  faults.schedule.classes=[jam,backlash,sensor_drift] faults.schedule.joints=[shoulder_lift,elbow,wrist_2]
  session.passes=2 session.progress=false"
for s in 1 2 3 4 99; do
  name=$([ $s = 99 ] && echo heldout || echo train_$s)
  # shellcheck disable=SC2086
  $PY -m robohealth_mj.record seed=$s $LEARNABLE hydra.run.dir=outputs/learnable/$name
done
for dev in cuda cpu; do
  $PY -m robohealth_mj.train variant=anomaly_residual seed=42 window=8 trainer.device=$dev \
    trainer.epochs=3 trainer.progress=false 'data.train=[outputs/learnable/train_*]' \
    data.evaluate.heldout=outputs/learnable/heldout data.evaluate.probe=null \
    out_dir=outputs/train_$dev
done > studies/fleet/results/cuda/train_cuda_check.txt
# 2026-11-27, on a lent machine (one NVIDIA H200; torch 2.11.0+cu130, torch-geometric 2.8.0.post1):
# the paths added since the check above (train labels=visible, evaluate observability=motion) on
# CUDA and on the CPU, for stgnn_fixed and anomaly_residual, on the same learnable corpus (recorded
# here as above, into outputs/learnable). The CPU rows equal those of a 2-core machine to the digit.
# (As run, the out_dir was /tmp/cc_<variant>_<device> and each step's exit status was printed.)
for dev in cuda cpu; do
  for variant in stgnn_fixed anomaly_residual; do
    $PY -m robohealth_mj.train variant=$variant seed=42 window=8 trainer.device=$dev \
      trainer.epochs=3 trainer.progress=false labels=visible 'data.train=[outputs/learnable/train_*]' \
      data.evaluate.heldout=outputs/learnable/heldout data.evaluate.probe=null \
      out_dir=outputs/visible_${variant}_$dev
    $PY -m robohealth_mj.evaluate ckpt=outputs/visible_${variant}_$dev/best.ckpt \
      data=outputs/learnable/heldout observability=motion device=$dev
  done
done > studies/fleet/results/cuda/train_visible_motion_check.txt
