#!/usr/bin/env bash
# Issue 36's networks on a lent GPU machine, as run on 2026-11-26 (one NVIDIA H200, 16 cores;
# 96 jobs in 8 minutes): each arm's training and held-out sessions recorded there, then every
# (sensing, stage, arm, variant, seed) trained at 30 epochs, PAR at a time (one CPU thread each,
# all on the one GPU; start CUDA MPS first where the machine has it), and the run directories
# packed to bring back. The rest runs where the full corpora are (results/arms/command.sh):
#   python experiments/arms/campaign.py --variants stgnn_fixed,anomaly_residual \
#     --steps rescore,commission,alarms
# From the repository root, with the package installed (pip install '.[full]').
set -euo pipefail
PY=${PY:-python3}
PAR=${PAR:-16}
for arm in ur5e ur10e ur3e ur16e; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir="outputs/corpus/arms/$arm" \
    "record_overrides=[\"arm=$arm\"]" progress=false jobs=4 '~corpus.healthy_commissioning' \
    '~corpus.healthy_hour' '~corpus.probe_payload_high' &
done
wait
# the stock profile has no sensor nodes, so no coupling head: stgnn_fixed alone there
for sensing in full stock; do
  variants=$([ $sensing = full ] && echo "stgnn_fixed anomaly_residual" || echo stgnn_fixed)
  for stage in loao own; do for arm in ur3e ur5e ur10e ur16e; do for variant in $variants; do
    for seed in 42 43 44; do echo "$sensing $stage $arm $variant $seed"; done
  done; done; done
done | xargs -P "$PAR" -L 1 sh -c '"$0" experiments/arms/campaign.py --steps train --epochs 30 \
  --sensing "$1" --stages "$2" --arms "$3" --variants "$4" --seeds "$5" \
  > "outputs/gpu_$1_$2_$3_$4_$5.log" 2>&1' "$PY"
tar -czf outputs/campaign_arms_gpu.tgz --exclude=tensorboard --exclude=.hydra outputs/campaign_arms
