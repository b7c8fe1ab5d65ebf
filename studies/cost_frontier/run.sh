#!/usr/bin/env bash
# Issue 66, part 1: what a monitored arm costs, as a frontier of diagnostic quality against
# MFLOP per stream-tick and streams sustained. One part per argument, into outputs/cost_frontier
# (a finished training run is skipped, so a part resumes after interruption):
#   bash studies/cost_frontier/run.sh train distill extra gbdt export quantise score online bench table
# train: the headline (anomaly_residual, W = 32, hidden 64) and its narrower forms, seeds 42-44
#   (FORMS, SEEDS to choose);
# extra: the shallower form, and the shorter window at seed 42; gbdt: the trees beside them, seed 42;
# single: the headline's encoder without the oldest snapshot's record (h64s), seeds as train;
#   then, after export and score, single_online, single_bench (idle machine), single_table
#   (results/single_record.md, the second pass);
# distill: STUDENTS (hidden 16; and with a snapshot MLP of 8) trained on the headline's soft
#   labels (the same seed's teacher: the same split, so no teacher saw a student's validation
#   windows);
# export: every run to ONNX with its incremental form;
# quantise: the headline (QUANTISED) as onnxruntime int8, dynamic and static (static
#   calibrated on a training session, never the held-out one);
# score: validation, held-out and probe accuracy / localisation of every ONNX model, through
#   onnxruntime;
# online: the monitor's on-line evaluation (episodes detected, latency, false alarms per healthy
#   hour) of the headline and of models run every k-th tick, seed 42 (ONLINE_SEEDS for more);
# bench: MFLOP per stream-tick and sustained streams (p99 <= 50 ms), all forms in one run;
# table: results/frontier.md and results/frontier.png.
# JOBS parallel runs of one thread each (default 2, for 2 cores). bench wants an idle machine.
set -euo pipefail
PY=${PY:-.venv/bin/python}
JOBS=${JOBS:-2}
ROOT=${ROOT:-outputs/cost_frontier}
CORPUS=${CORPUS:-outputs/corpus/standard}
SEEDS=${SEEDS:-42 43 44}
HERE=studies/cost_frontier
# name and overrides of each form (the headline first: the students' teachers)
FORMS=${FORMS:-h64 h32 h16 h16c8}
STUDENTS=${STUDENTS:-h16c8 h16}
declare -A FORM=(
  [h64]=""                                     # the headline
  [h32]="model.hidden=32"                      # narrower
  [h16]="model.hidden=16"
  [h16c8]="model.hidden=16 model.backbone.channels=8"  # + a narrower snapshot MLP
  [h64_l1]="model.backbone.layers=1"           # shallower: one message-passing layer
  [h16_w16]="model.hidden=16 window=16"        # a shorter window (0.8 s)
  [h64s]="model.backbone.first_record=false"   # no snapshot-MLP record of the window's oldest
)                                              # snapshot: one record a sample in the fleet
run() {  # out_dir, then overrides: one training run of one thread
  local out=$1; shift
  $PY -m robohealth_mj.train variant=anomaly_residual window=32 threads=1 \
    trainer.progress=false "data.train=[$CORPUS/train_*]" \
    data.evaluate.heldout="$CORPUS/heldout_seed900" \
    data.evaluate.probe="$CORPUS/probe_payload_high_seed901" \
    out_dir="$ROOT/$out" "$@" >"$ROOT/logs/${out//\//_}.log" 2>&1 || echo "failed: $out" >&2
}
source studies/parallel_runs.sh  # parallel_runs: JOBS of these runs at a time
for part in "$@"; do
  case $part in
    train)
      for form in $FORMS; do for seed in $SEEDS; do
        echo "$form/seed$seed seed=$seed${FORM[$form]:+ ${FORM[$form]}}"  # no trailing blank (xargs -L)
      done; done | parallel_runs ;;
    extra)  # the shallower form (seeds as train) and the shorter window (seed 42)
      FORMS=h64_l1 bash "$0" train
      FORMS=h16_w16 SEEDS=42 bash "$0" train ;;
    single) FORMS=h64s bash "$0" train ;;
    single_online)  # the second pass: h64s on-line at seed 42, and both forms at seeds 43-44
      ONLINE="h64s@1 h64s@4 h64s@5 h64s@6 h64@5" bash "$0" online
      ONLINE_SEEDS="43 44" ONLINE="h64s@1 h64s@4 h64@4" bash "$0" online ;;
    single_bench)  # three bench runs (a machine's bursts move one search by 20 %): medians
      for i in "" _2 _3; do BENCH_OUT=$HERE/results/bench_single$i.txt bash "$0" bench; done
      for spec in "h64 1" "h64 4" "h64s 4"; do  # where a stream-tick's thread time goes
        set -- $spec
        $PY -m robohealth_mj.bench streams --model "$ROOT/$1/seed42/model.onnx" \
          --data "$CORPUS/heldout_seed900" --decide-every "$2" --profile 4000
      done > $HERE/results/profile_single.txt ;;
    single_table) $PY $HERE/summarise.py "$ROOT" $HERE/results --name single_record \
      --bench bench_single.txt bench_single_2.txt bench_single_3.txt ;;
    gbdt)  # the reference beside the networks (trees: no fleet form), seed 42
      echo "gbdt/seed42 variant=gbdt seed=42" | parallel_runs ;;
    distill)
      for form in $STUDENTS; do for seed in $SEEDS; do
        teacher=$ROOT/h64/seed$seed/best.ckpt
        [ -f "$teacher" ] || { echo "no teacher $teacher: run the train part first" >&2; exit 2; }
        echo "${form}_kd/seed$seed seed=$seed ${FORM[$form]} trainer.distill.teacher=$teacher"
      done; done | parallel_runs ;;
    export)
      for ckpt in "$ROOT"/*/seed*/best.ckpt; do
        d=$(dirname "$ckpt")
        case $d in */gbdt/*) continue ;; esac  # trees: no ONNX form
        [ -f "$d/eval_heldout.json" ] || continue  # still training
        [ -f "$d/model.onnx" ] || $PY -m robohealth_mj.export ckpt="$ckpt" out="$d/model.onnx" \
          2>&1 | grep -v torchvision
      done ;;
    quantise)  # static: calibrated on the checkpoint's first training session
      for form in ${QUANTISED:-h64}; do for seed in $SEEDS; do
        d=$ROOT/$form/seed$seed
        [ -f "$d/eval_heldout.json" ] || continue
        for mode in dynamic static; do
          [ -f "$d/model_int8${mode:0:1}.onnx" ] || $PY -m robohealth_mj.export \
            ckpt="$d/best.ckpt" out="$d/model_int8${mode:0:1}.onnx" quantise=$mode \
            2>&1 | grep -v torchvision
        done
      done; done ;;
    score)
      pairs=()
      for m in "$ROOT"/*/seed*/model*.onnx; do pairs+=("$m=$(dirname "$m")/best.ckpt"); done
      $PY $HERE/score.py "${pairs[@]}" --out "$ROOT/scores.json" --data val=val \
        heldout="$CORPUS/heldout_seed900" probe="$CORPUS/probe_payload_high_seed901" ;;
    bench)  # seed 42's file of each architecture (a distilled student costs as its form);
      # FORM/FILE@K: run every K-th tick of a stream. Wants an idle machine.
      models=()
      for m in h64/seed42/model.onnx h64/seed42/model_int8d.onnx h64/seed42/model_int8s.onnx \
               h32/seed42/model.onnx h16/seed42/model.onnx h16c8/seed42/model.onnx \
               h64_l1/seed42/model.onnx h64/seed42/model.onnx@4 h64/seed42/model.onnx@6 \
               h64_l1/seed42/model.onnx@4 h32/seed42/model.onnx@4 h64s/seed42/model.onnx \
               h64s/seed42/model.onnx@4 h64s/seed42/model.onnx@6; do
        [ -f "$ROOT/${m%@*}" ] && models+=("$ROOT/$m")
      done
      $PY -m robohealth_mj.bench streams --compare "${models[@]}" --data "$CORPUS/heldout_seed900" \
        --start 1000 --limit 32768 > "${BENCH_OUT:-$HERE/results/bench_compare.txt}" ;;
    online)  # the monitor's on-line evaluation at its default alarm settings, seed 42: the
      # headline every tick, and ONLINE's FORM@K (the model every K-th tick of an arm). Chosen on
      # a selection session (seed 902, recorded as the held-out one) and an hour of healthy
      # running (seed 903); the held-out session is reported, never chosen on.
      [ -f "$ROOT/selection902/graphs.jsonl" ] || $PY -m robohealth_mj.record seed=902 \
        "curriculum.speed_scales=[0.6,1.0,1.5]" "curriculum.payload_scales=[0.5,1.0,1.6]" \
        session.passes=1 session.progress=false hydra.run.dir="$ROOT/selection902"
      [ -f "$ROOT/healthy903/graphs.jsonl" ] || $PY -m robohealth_mj.record seed=903 faults=none \
        session.duration_s=3600 session.progress=false hydra.run.dir="$ROOT/healthy903"
      for seed in ${ONLINE_SEEDS:-42}; do  # ONLINE_SEEDS: other seeds' models too (files _sN)
        tag=$([ "$seed" = 42 ] || echo "_s$seed")
        for entry in h64@1 ${ONLINE:-h64@2 h64@4 h64@6 h64@8 h32@2 h32@4}; do
          form=${entry%@*} k=${entry#*@}
          for set in selection:$ROOT/selection902 healthy:$ROOT/healthy903 \
                     heldout:$CORPUS/heldout_seed900; do
            out=$HERE/results/online/${form}_k${k}${tag}_${set%%:*}.json
            [ -f "$out" ] || $PY -m robohealth_mj.monitor \
              model="$ROOT/$form/seed$seed/model.onnx" source=replay \
              file="${set#*:}/graphs.jsonl" evaluate=true quiet=true decide_every="$k" threads=1 \
              out="$out"
          done
        done
      done ;;
    table) $PY $HERE/summarise.py "$ROOT" $HERE/results ;;
    *) echo "unknown part: $part" >&2; exit 2 ;;
  esac
done
