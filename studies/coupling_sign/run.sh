#!/usr/bin/env bash
# Issue 69: the coupling whose sign is pinned by construction (model.coupling_fit=motion) against
# the thesis's learned one, on the unknown-placement harness. One part per argument, runs into
# outputs/coupling_sign (a finished run is skipped, so a part resumes after interruption):
#   bash studies/coupling_sign/run.sh fits default placements weights pose summary
# fits: the motion fit alone (no training) on placements 1-10, full profile, split seed 42
# (the fit reads position, velocity and the sensors, which retrofit keeps: the same C; and
# C0's fit is the same to 3 decimals on seeds 42-44; FIT_SEEDS="42 43 44" for all three);
# default: anomaly_residual on the default placement C0, full and retrofit, seeds 42-44 (Table 8);
# placements: anomaly_residual on placements 1, 2, 3, 5 (those of studies/thesis_physics), seed 42;
# weights: the reconstruction weight at WEIGHTS (default "0.3 1.0"), both fits (C0, full, seed 42);
# pose: pose_anomaly as default, seeds SEEDS (default "42 43 44");
# joint: the motion fit with a per-joint score beside the scattered ones (model.anomaly_joint_scores),
# which breaks the tie of joints a sparse placement couples alike: placements 1 and 2, full, then
# C0 full and placement 1 retrofit (seed 42).
# joint_more: the same form on C0 at seeds 43 and 44 (full) and 42-44 (retrofit), on placements 3
# and 5 (full) and on placement 2 (retrofit), seed 42 where not said.
# epochs: the C0 retrofit runs (motion fit; FORMS: motion, motion_joint (joint scores),
# motion_joint_coupled (and the joint-sensor edges set by C)) at EPOCHS; known: the known
# placement's (structural graph, the thesis's recipe) at EPOCHS, the ceiling to compare with;
# coupled: the form chosen there (joint scores, coupled edges, 40 epochs) on C0 full, seeds
# 42-44, and on placements 1 and 2 full, seed 42; given: that form told the true placement
# (C0 retrofit, 42-44), the ceiling on the same four sensors.
# grid: that recipe and gbdt on all ten placements (placement_fits.py's), GRID_PROFILES (default
# both) at GRID_SEEDS (default 42); archive: the finished runs' records into results/runs
# (committed); grid_table: results/grid.md from that archive.
# JOBS parallel runs of one thread each (default 2, for 2 cores).
set -euo pipefail
PY=${PY:-.venv/bin/python}
JOBS=${JOBS:-2}
ROOT=${ROOT:-outputs/coupling_sign}
CORPUS=${CORPUS:-outputs/corpus/standard}
HERE=studies/coupling_sign

run() {  # out_dir, then overrides: one training run of one thread
  local out=$1 base=(graph=harness model.anomaly_scores=energy); shift
  [[ " $* " == *" variant=gbdt "* ]] && base=(graph=harness)  # the trees have no anomaly scores
  [[ " $* " == *" graph="* ]] && base=()  # another graph: the thesis's recipe for it
  $PY -m robohealth_mj.train window=32 "${base[@]}" \
    threads=1 trainer.progress=false "data.train=[$CORPUS/train_*]" \
    data.evaluate.heldout="$CORPUS/heldout_seed900" '~data.evaluate.probe' \
    out_dir="$ROOT/$out" "$@" >"$ROOT/logs/${out//\//_}.log" 2>&1 || echo "failed: $out" >&2
}
source studies/parallel_runs.sh  # parallel_runs: JOBS of these runs at a time
joint_line() {  # "name:profile:coupling_seed:coupling_sensors:seed" -> one joint-score run line
  local name s cs cm seed place="" part=placements
  IFS=: read -r name s cs cm seed <<<"$1"
  [ -n "$cs" ] && place="graph.coupling_seed=$cs graph.coupling_sensors=$cm"
  [ "$name" = C0 ] && part=default
  # no trailing blank: xargs -L would join the next line to this one
  echo "$part/$s/$name/anomaly_residual_motion_joint/seed$seed variant=anomaly_residual" \
    "sensing=$s seed=$seed model.coupling_fit=motion model.anomaly_joint_scores=true${place:+ $place}"
}
for part in "$@"; do
  case $part in
    fits) seeds=${FIT_SEEDS:-42}
          $PY $HERE/placement_fits.py --corpus "$CORPUS" --out $HERE/results/fits.json \
            --seeds "${seeds// /,}" --profiles full ;;
    default)
      for seed in 42 43 44; do for s in full retrofit; do for fit in motion losses; do
        [ $fit = losses ] && continue  # the thesis's rows: studies/thesis_physics (same recipe)
        echo "default/$s/C0/anomaly_residual_$fit/seed$seed variant=anomaly_residual" \
          "sensing=$s seed=$seed model.coupling_fit=$fit"
      done; done; done | parallel_runs ;;
    placements)
      for p in 1:3 2:4 3:6 5:4; do for s in full retrofit; do
        echo "placements/$s/seed${p%:*}_m${p#*:}/anomaly_residual_motion/seed42" \
          "variant=anomaly_residual sensing=$s seed=42 model.coupling_fit=motion" \
          "graph.coupling_seed=${p%:*} graph.coupling_sensors=${p#*:}"
      done; done | parallel_runs ;;
    weights)
      for w in ${WEIGHTS:-0.3 1.0}; do for fit in motion losses; do
        echo "weights/full/C0/anomaly_residual_${fit}_w$w/seed42 variant=anomaly_residual" \
          "sensing=full seed=42 model.coupling_fit=$fit trainer.recon_loss_weight=$w"
      done; done | parallel_runs ;;
    pose)
      for seed in ${SEEDS:-42 43 44}; do for s in full retrofit; do
        echo "default/$s/C0/pose_anomaly_motion/seed$seed variant=pose_anomaly sensing=$s" \
          "seed=$seed model.coupling_fit=motion"
      done; done | parallel_runs ;;
    joint)
      for p in seed1_m3:full:1:3:42 seed2_m4:full:2:4:42 C0:full:::42 seed1_m3:retrofit:1:3:42; do
        joint_line "$p"
      done | parallel_runs ;;
    joint_more)
      for p in C0:full:::43 C0:full:::44 C0:retrofit:::42 C0:retrofit:::43 C0:retrofit:::44 \
               seed3_m6:full:3:6:42 seed5_m4:full:5:4:42 seed2_m4:retrofit:2:4:42; do
        joint_line "$p"
      done | parallel_runs ;;
    epochs)  # C0 retrofit, motion fit, FORMS trained for EPOCHS (default 40; patience 8), 42-44
      e=${EPOCHS:-40}
      for seed in 42 43 44; do for form in ${FORMS:-motion motion_joint}; do
        extra=""
        [[ $form == *joint* ]] && extra+=" model.anomaly_joint_scores=true"
        [[ $form == *coupled* ]] && extra+=" model.coupled_edges=true"
        echo "default/retrofit/C0/anomaly_residual_${form}_e$e/seed$seed variant=anomaly_residual" \
          "sensing=retrofit seed=$seed model.coupling_fit=motion trainer.epochs=$e" \
          "trainer.patience=8$extra"
      done; done | parallel_runs ;;
    grid)
      fits="import sys; sys.path.insert(0, '$HERE'); import placement_fits as f"
      places=$($PY -c "$fits; print(f.PLACEMENTS)")  # the placements the fits cover
      for seed in ${GRID_SEEDS:-42}; do for s in ${GRID_PROFILES:-full retrofit}; do
      for p in ${places//,/ }; do
        joint_line "seed${p%:*}_m${p#*:}:$s:${p%:*}:${p#*:}:$seed"
        echo "placements/$s/seed${p%:*}_m${p#*:}/gbdt/seed$seed variant=gbdt sensing=$s" \
          "seed=$seed graph.coupling_seed=${p%:*} graph.coupling_sensors=${p#*:}"
      done; done; done | parallel_runs ;;
    coupled)  # the chosen form on C0 full (42-44) and on sparse placements 1 and 2 (full, 42)
      form=+experiment=unknown_placement  # the motion fit, joint scores, C as edges, 40 epochs
      {
        for seed in 42 43 44; do
          echo "default/full/C0/anomaly_residual_motion_joint_coupled_e40/seed$seed" \
            "variant=anomaly_residual sensing=full seed=$seed $form"
        done
        for p in 1:3 2:4; do
          place=placements/full/seed${p%:*}_m${p#*:}
          echo "$place/anomaly_residual_motion_joint_coupled_e40/seed42 variant=anomaly_residual" \
            "sensing=full seed=42 $form graph.coupling_seed=${p%:*}" \
            "graph.coupling_sensors=${p#*:}"
        done
      } | parallel_runs ;;
    given)  # the chosen form told the true placement (frozen): the same sensors, C known
      for seed in 42 43 44; do
        echo "default/retrofit/C0/anomaly_residual_given_joint_coupled_e40/seed$seed" \
          "variant=anomaly_residual sensing=retrofit seed=$seed +experiment=unknown_placement" \
          "model.coupling_fit=given"
      done | parallel_runs ;;
    known)  # the known placement (structural graph), retrofit, EPOCHS (default 40), 42-44
      e=${EPOCHS:-40}
      for seed in 42 43 44; do
        echo "default/retrofit/C0/known_anomaly_residual_e$e/seed$seed variant=anomaly_residual" \
          "sensing=retrofit seed=$seed graph=structural trainer.epochs=$e trainer.patience=8"
      done | parallel_runs ;;
    archive)  # each finished run's summary and held-out figures, nothing heavier
      for f in "$ROOT"/placements/*/*/*/seed*/{train_summary,eval_heldout}.json; do
        [ -f "$f" ] || continue
        dest=$HERE/results/runs/${f#"$ROOT"/placements/}
        mkdir -p "$(dirname "$dest")" && cp "$f" "$dest"
      done
      for f in "$ROOT"/default/*/C0/*/seed*/{train_summary,eval_heldout}.json; do
        [ -f "$f" ] || continue
        dest=$HERE/results/runs/${f#"$ROOT"/}
        mkdir -p "$(dirname "$dest")" && cp "$f" "$dest"
      done ;;
    grid_table) $PY $HERE/summarise.py --grid $HERE/results/grid.md ;;
    summary) $PY $HERE/summarise.py --root "$ROOT" --out $HERE/results/results.md ;;
    *) echo "unknown part: $part" >&2; exit 2 ;;
  esac
done
