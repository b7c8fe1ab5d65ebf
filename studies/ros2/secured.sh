#!/usr/bin/env bash
# The monitor on an SROS2-secured graph against an open one (issue 67): 25 arms, both layouts,
# each row open then secured in one run, on the secured binding for both (make setup-sros2),
# three runs in a row. Latency p99 secured / open is the figure (docs/ros2_live.md, Benchmark).
set -euo pipefail
PY=${PY:-.venv-sros2/bin/python}
DATA=${DATA:-outputs/corpus/standard/heldout_seed900}
OUT=studies/ros2/results/bench_sros2.txt
{
  echo "# $PY -m robohealth_mj.bench ros2 --model full --data $DATA --arms 25 --layouts per_sensor aggregated --graphs open secured"
  echo "# three runs in a row; $(date -u +%F)"
  for round in 1 2 3; do
    echo "## round $round"
    $PY -m robohealth_mj.bench ros2 --model full --data "$DATA" --arms 25 \
      --layouts per_sensor aggregated --graphs open secured
  done
} | tee "$OUT"
