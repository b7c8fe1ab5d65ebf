#!/usr/bin/env bash
# The thesis's experiment on physics (campaign issue), one block per argument, all into
# outputs/thesis_physics (a finished run is skipped, so any block resumes after interruption):
#   bash studies/thesis_physics/run.sh corpus matrix matrix_w32 windows harness retrofit_known placements severity stock report
# (harness = harness_fixed + harness_coupling, either half runnable alone)
# JOBS parallel runs of one thread each (default 2, for 2 cores); TRAIN_ARGS adds overrides to every
# run (e.g. "trainer.device=cuda variant=mlp,gat"); CORPUS names the corpus directory.
set -euo pipefail
PY=${PY:-.venv/bin/python}
JOBS=${JOBS:-2}
ROOT=${ROOT:-outputs/thesis_physics}
CORPUS=${CORPUS:-outputs/corpus/standard}
# shellcheck disable=SC2206
EXTRA=(${TRAIN_ARGS:-})
train() {
  $PY -m robohealth_mj.train -m hydra/launcher=local hydra.launcher.n_jobs="$JOBS" \
    threads=1 trainer.progress=false hydra.sweep.dir="$ROOT" \
    "data.train=[$CORPUS/train_*]" data.evaluate.heldout="$CORPUS/heldout_seed900" \
    data.evaluate.probe="$CORPUS/probe_payload_high_seed901" "${EXTRA[@]}" "$@"
}
timed() {  # block name, then the command; appends the block's wall time to $ROOT/blocks.tsv
  local name=$1 t0; shift; t0=$(date +%s)
  "$@"
  mkdir -p "$ROOT"; printf '%s\t%s\t%s\t%s\n' "$name" "$(( $(date +%s) - t0 ))" "$JOBS" \
    "$(hostname)" >>"$ROOT/blocks.tsv"
}
for block in "$@"; do
  case $block in
    corpus) timed corpus $PY -m robohealth_mj.corpus corpus=standard progress=false ;;
    matrix) timed matrix train +experiment=thesis_matrix ;;
    matrix_w32) timed matrix_w32 train +experiment=thesis_matrix_w32 ;;
    windows) timed windows train +experiment=window_ablation ;;
    harness) timed harness train +experiment=harness
             timed harness_coupling train +experiment=harness_coupling ;;
    harness_fixed) timed harness train +experiment=harness ;;  # the harness's first half alone
    harness_coupling) timed harness_coupling train +experiment=harness_coupling ;;  # second half
    placements)
      for p in 1:3 2:4 3:6 4:8 5:4; do
        set -- graph.coupling_seed="${p%:*}" graph.coupling_sensors="${p#*:}"
        timed "placement_${p%:*}" train +experiment=placements "$@" variant=gbdt
        timed "placement_${p%:*}_coupling" train +experiment=placements "$@" \
          variant=anomaly_residual model.anomaly_scores=energy
      done ;;
    retrofit_known)  # the retrofit profile with the placement known (structural graph): its ceiling
      timed retrofit_known train window=32 sensing=retrofit variant=gbdt,anomaly_residual seed=42 ;;
    severity) timed severity train +experiment=severity ;;
    stock) timed stock train +experiment=stock ;;  # the stock arm (studies/stock_arm/results/)
    # The finished runs' records go into the committed archive (runs/), and the report is built
    # from it: every run archived so far, from any machine, not only those still in $ROOT.
    report) $PY -m robohealth_mj.report "$ROOT" --archive studies/thesis_physics/results/runs \
              --out studies/thesis_physics/results ;;
    *) echo "unknown block: $block" >&2; exit 2 ;;
  esac
done
