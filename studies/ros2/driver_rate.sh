#!/usr/bin/env bash
# The UR driver's rate at fleet scale (issue 66, part 3): /joint_states and the trajectory
# controller's state at 500 Hz an arm, 25 times the model's rate. Arms per monitor process with no
# loss, before (every message decoded: the monitor of BEFORE, default 3eb36e2) and after (a joint
# state between ticks passed over from its 8 stamp bytes, a controller state decoded only when a
# tick takes it). The "before" side runs the same benchmark code in a worktree of BEFORE.
set -euo pipefail
PY=${PY:-$PWD/.venv/bin/python}
BEFORE=${BEFORE:-3eb36e2}
DATA=${DATA:-$PWD/outputs/corpus/standard/heldout_seed900}
OUT=studies/ros2/results/driver_rate.txt
ARGS=(--model ur_driver --data "$DATA" --layouts ur_driver --driver-hz 500 --seconds 10)
tree=$(mktemp -d)/before
git worktree add -q "$tree" "$BEFORE"
trap 'git worktree remove --force "$tree"' EXIT
cp robohealth_mj/benchmarks/ros2.py robohealth_mj/benchmarks/cli.py "$tree/robohealth_mj/benchmarks/"
{
  echo "# bench ros2 ${ARGS[*]}; $(date -u +%F); before = $BEFORE's monitor, after = this checkout's"
  echo "## before"
  (cd "$tree" && PYTHONPATH="$tree" $PY -m robohealth_mj.bench ros2 "${ARGS[@]}" --arms 25 50)
  echo "## after"
  $PY -m robohealth_mj.bench ros2 "${ARGS[@]}" --arms 25 50 75 100
  echo "## after, two monitor processes"
  $PY -m robohealth_mj.bench ros2 "${ARGS[@]}" --arms 100 --monitors 2
} 2>&1 | grep -v "^runtime" | tee "$OUT"
