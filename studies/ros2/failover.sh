#!/usr/bin/env bash
# Monitors that cover for each other (issue 66, part 2): three monitor processes sharing 30 arms
# on loopback through ros2.group (heartbeats on /robohealth/monitor_group, rendezvous hashing).
# Ten cycles: one monitor killed with SIGKILL, then restarted under its name. Per cycle: how soon
# its arms are diagnosed again by the others, ticks diagnosed twice from 3 s after the kill,
# ticks lost outside the gap, and how soon the restarted one holds its share again.
set -euo pipefail
PY=${PY:-$PWD/.venv/bin/python}
DATA=${DATA:-$PWD/outputs/corpus/standard/heldout_seed900}
OUT=studies/ros2/results/failover.txt
ARGS=(--model full --data "$DATA" --monitors 3 --arms 30 --kill 1 --cycles 10)
{
  echo "# bench ros2 ${ARGS[*]}; $(date -u +%F)"
  $PY -m robohealth_mj.bench ros2 "${ARGS[@]}"
} 2>&1 | grep -v "^runtime" | tee "$OUT"
