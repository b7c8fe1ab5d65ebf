#!/usr/bin/env bash
# Issue 36's networks on a lent GPU machine (one NVIDIA H200, 16 cores): each arm's training and
# held-out sessions recorded there and parsed once into their array caches, then every job
# (sensing, stage, arm, variant, seed) trained at 30 epochs, PAR at a time (one CPU thread each,
# all on the one GPU), and the run directories packed to bring back. The rest runs where the full
# corpora are (studies/arms/run.sh):
#   python studies/arms/campaign.py --out "$CAMPAIGN" --variants stgnn_fixed,anomaly_residual \
#     --steps rescore,commission,alarms
# From the repository root, with the package importable.
#   studies/arms/gpu_networks.sh [JOBS_FILE]
# JOBS_FILE holds one job per line, "sensing stage arm variant seed"; without it, the campaign of
# 2026-11-26 (96 jobs, 8 minutes): both variants (stgnn_fixed alone on the stock profile, which has
# no sensor nodes for a coupling head), own and leave-one-arm-out, seeds 42-44.
# Environment: PY (python), PAR (jobs at a time, 16), CAMPAIGN (campaign root,
# outputs/campaign_arms), BUDGET_S (seconds from this script's start after which the trainings are
# stopped, so that the runs that finished are packed inside a lease), PACK (the archive,
# outputs/campaign_arms_gpu.tgz), CORPUS (the per-arm corpora's root, outputs/corpus/arms),
# CORPUS_OVERRIDES (more corpus overrides, space-separated, e.g. corpus.train.sessions=16 for twice
# the training sessions per arm). Start CUDA MPS first where the machine has it.
set -euo pipefail
PY=${PY:-python3}
PAR=${PAR:-16}
export CAMPAIGN=${CAMPAIGN:-outputs/campaign_arms}
BUDGET_S=${BUDGET_S:-3600}
PACK=${PACK:-outputs/campaign_arms_gpu.tgz}
export CORPUS=${CORPUS:-outputs/corpus/arms}
read -r -a MORE <<< "${CORPUS_OVERRIDES:-}"

all_jobs() {
  for sensing in full stock; do
    variants=$([ $sensing = full ] && echo "stgnn_fixed anomaly_residual" || echo stgnn_fixed)
    for stage in loao own; do for arm in ur3e ur5e ur10e ur16e; do for variant in $variants; do
      for seed in 42 43 44; do echo "$sensing $stage $arm $variant $seed"; done
    done; done; done
  done
}

for arm in ur5e ur10e ur3e ur16e; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir="$CORPUS/$arm" \
    "record_overrides=[\"arm=$arm\"]" progress=false jobs=4 '~corpus.healthy_commissioning' \
    '~corpus.healthy_hour' '~corpus.probe_payload_high' '~corpus.validation' ${MORE[@]+"${MORE[@]}"} &
done
wait
for arm in ur5e ur10e ur3e ur16e; do
  [ -f "$CORPUS/$arm/corpus.json" ] || { echo "no corpus recorded for $arm" >&2; exit 1; }
done
# every training reads all of these: parse each once here rather than once per job
ls "$CORPUS"/*/*/graphs.jsonl | xargs -P "$PAR" -I{} "$PY" -c \
  "from robohealth_mj.data.arrays import load_recordings; load_recordings(['{}'])"
echo "corpora parsed after $SECONDS s"
mkdir -p outputs/gpu_logs
{ if [ $# -ge 1 ]; then cat "$1"; else all_jobs; fi; } |
  timeout $((BUDGET_S - SECONDS)) xargs -P "$PAR" -L 1 sh -c '"$0" studies/arms/campaign.py \
    --out "$CAMPAIGN" --corpus "$CORPUS" --steps train --epochs 30 --sensing "$1" --stages "$2" \
    --arms "$3" --variants "$4" --seeds "$5" > "outputs/gpu_logs/$1_$2_$3_$4_$5.log" 2>&1
    echo "$1 $2 $3 $4 $5 rc=$?" >> outputs/gpu_logs/done.txt' "$PY" &&
  echo "trainings done after $SECONDS s" ||
  echo "trainings stopped (exit $?) after $SECONDS s: packing the runs that finished"
tar -czf "$PACK" --exclude=tensorboard --exclude=.hydra "$CAMPAIGN" outputs/gpu_logs
