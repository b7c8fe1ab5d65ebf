#!/usr/bin/env bash
# The deployment-speed issue's measurements: the runtime before the change (BEFORE, a git
# worktree) and after it (this checkout), on one machine, one after the other, nothing else
# running (2 cores; the benchmarks time 50 ms ticks and DDS latency). About 45 min.
#   BEFORE=4ecece7 bash studies/fleet/run_speed.sh
# Outputs: studies/fleet/results/speed (the fleet step, decisions), studies/ros2/results/speed (live over DDS).
set -euo pipefail
PY=${PY:-$PWD/.venv/bin/python}  # the venv's own (realpath would resolve it to the base interpreter)
BEFORE=${BEFORE:-4ecece7}
OUT=studies/fleet/results/speed
LIVE=studies/ros2/results/speed  # the live path's outputs
M=$(realpath studies/earlier_campaigns/results/headline_physics/anomaly_residual_w32_seed42.onnx)
D=outputs/bench_replay/heldout_seed900
# a 15-minute held-out-seed session to replay (any recording serves: only its values' spread matters)
[ -f $D/graphs.jsonl ] || $PY -m robohealth_mj.record seed=900 session.duration_s=900 \
  session.progress=false hydra.run.dir=$D
D=$(realpath $D)
[ -d outputs/before_speed ] || git worktree add -f outputs/before_speed "$BEFORE"
here=$PWD
run_before() { (cd outputs/before_speed && "$PY" -m robohealth_mj.bench "$@"); }  # its own package first
run_after() { "$PY" -m robohealth_mj.bench "$@"; }
# decisions on a replay (300 streams, 1,200 ticks, gaps and bursts): the digests must match
(cd outputs/before_speed && "$PY" "$here/studies/fleet/decisions.py" --model $M --data $D \
  --out "$here/outputs/decisions_before.npz") > $OUT/decisions.txt
$PY studies/fleet/decisions.py --model $M --data $D --out outputs/decisions_after.npz >> $OUT/decisions.txt
# the fleet step: where the time goes, the sustained count (search), 2,000 paced for 60 s
# (profile_before.txt was taken on BEFORE with only the phase clock added, before any change)
run_before streams --model $M --data $D --streams 2000 --seconds 60 --memory-rounds 1 > $OUT/streams_before.txt
run_after streams --model $M --data $D --streams 2000 --seconds 60 --memory-rounds 1 > $OUT/streams_after.txt
run_after streams --model $M --data $D --profile 1000 2000 4000 > $OUT/profile_after.txt
# live over DDS: per-sensor and aggregated layouts; then /health_diagnosis at 1 Hz; then two monitors
run_before ros2 --model $M --data $D --arms 25 50 --layouts per_sensor > $LIVE/ros2_before.txt
run_before ros2 --model $M --data $D --arms 50 100 --layouts aggregated | tail -n +2 >> $LIVE/ros2_before.txt
run_after ros2 --model $M --data $D --arms 25 35 50 100 --layouts per_sensor > $LIVE/ros2_after.txt
run_after ros2 --model $M --data $D --arms 50 100 150 200 --layouts aggregated | tail -n +2 >> $LIVE/ros2_after.txt
run_after ros2 --model $M --data $D --arms 50 100 --layouts per_sensor --monitors 2 > $LIVE/ros2_after_scaleout.txt
# /health_diagnosis at 1 Hz (measured before the diagnoses were written as bytes; at 1 Hz they
# cost 0.02 cores either way)
run_after ros2 --model $M --data $D --arms 50 100 --layouts per_sensor --health-hz 1 > $LIVE/ros2_after_health1.txt
run_after ros2 --model $M --data $D --arms 35 --layouts per_sensor --health-hz 1 >> $LIVE/ros2_after_health1.txt
run_after ros2 --model $M --data $D --arms 100 150 200 --layouts aggregated --health-hz 1 \
  | tail -n +2 >> $LIVE/ros2_after_health1.txt
run_after ros2 --model $M --data $D --arms 50 100 --layouts per_sensor --monitors 2 --health-hz 1 \
  > $LIVE/ros2_after_scaleout_health1.txt
# the take and the decoding timed apart (after the runs above)
run_after ros2 --model $M --data $D --arms 25 35 --layouts per_sensor > $LIVE/ros2_after_phases.txt
