#!/usr/bin/env bash
# The live path's second step (issue 38): byte templates, a waitset of the ready readers, one
# runtime step a fleet tick. The runtime before it (BEFORE, a git worktree) and after it (this
# checkout), one after the other on one machine with nothing else running. About 12 min.
#   BEFORE=bd79e57 bash studies/ros2/run_templates.sh
set -euo pipefail
PY=${PY:-$PWD/.venv/bin/python}  # the venv's own (realpath would resolve it to the base interpreter)
BEFORE=${BEFORE:-bd79e57}
LIVE=studies/ros2/results/speed
M=$(realpath studies/earlier_campaigns/results/headline_physics/anomaly_residual_w32_seed42.onnx)
D=outputs/bench_replay/heldout_seed900
# a held-out-seed session to replay (any recording serves: only its values' spread matters)
[ -f $D/graphs.jsonl ] || $PY -m robohealth_mj.record seed=900 session.duration_s=60 \
  session.progress=false hydra.run.dir=$D
D=$(realpath $D)
[ -d outputs/before_live ] || git worktree add -f outputs/before_live "$BEFORE"
run_before() { (cd outputs/before_live && "$PY" -m robohealth_mj.bench "$@"); }  # its own package first
run_after() { "$PY" -m robohealth_mj.bench "$@"; }
{
  run_before ros2 --model $M --data $D --arms 25 50 75 100 --layouts per_sensor
  run_before ros2 --model $M --data $D --arms 100 150 200 --layouts aggregated | tail -n +2
} > $LIVE/templates_before.txt
{
  run_after ros2 --model $M --data $D --arms 25 50 75 100 --layouts per_sensor
  run_after ros2 --model $M --data $D --arms 100 150 200 250 --layouts aggregated | tail -n +2
  run_after ros2 --model $M --data $D --arms 75 100 --layouts per_sensor --health-hz 1 | tail -n +2
  run_after ros2 --model $M --data $D --arms 100 --layouts per_sensor --monitors 2 | tail -n +2
  run_after ros2 --model $M --data $D --arms 200 250 --layouts aggregated --health-hz 1 | tail -n +2
} > $LIVE/templates_after.txt
# what DDS alone costs: the publishers, and a monitor process that only receives or only takes
$PY studies/ros2/transport_floor.py --data $D --arms 50 100 > $LIVE/transport_floor.txt
# the one new setting, chosen by measurement: how long a completed sample waits for the others
for w in 0 0.01 0.02 0.04; do
  echo "# diagnose_wait_s=$w"
  run_after ros2 --model $M --data $D --arms 25 50 --layouts per_sensor --diagnose-wait-s $w
done > $LIVE/diagnose_wait.txt
# the monitor's work alone (no DDS): decode and assembly by path, a runtime step by batch size
$PY studies/ros2/monitor_costs.py --data $D --model $M > $LIVE/monitor_costs.txt
