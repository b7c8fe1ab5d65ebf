#!/usr/bin/env bash
# ROS 2 over DDS on loopback (2 cores, nothing else running): arms per monitor process at 20 Hz,
# both layouts; publishers in a child process replaying the quick corpus's held-out session.
set -euo pipefail
PY=${PY:-.venv/bin/python}
$PY -m robohealth_mj.bench ros2 --model studies/faint_faults/results/anomaly_residual_w32_seed42.onnx \
  --data outputs/corpus/quick/heldout_seed900 --arms 10 25 50 75 --seconds 15 | tee studies/ros2/results/bench_ros2.txt
# The deployment-speed issue before/after (fast decoding, diagnoses as bytes, scale-out):
# studies/fleet/run_speed.sh writes its live figures to studies/ros2/results/speed/.
