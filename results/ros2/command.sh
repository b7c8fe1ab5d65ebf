#!/usr/bin/env bash
# ROS 2 over DDS on loopback (2 cores, nothing else running): arms per monitor process at 20 Hz,
# both layouts; publishers in a child process replaying the quick corpus's held-out session.
set -euo pipefail
PY=${PY:-.venv/bin/python}
$PY -m robohealth_mj.bench ros2 --model results/faint_faults/anomaly_residual_w32_seed42.onnx \
  --data outputs/corpus/quick/heldout_seed900 --arms 10 25 50 75 --seconds 15 | tee results/ros2/bench_ros2.txt
# The deployment-speed issue before/after (fast decoding, diagnoses as bytes, scale-out):
# results/fleet/speed/command.sh writes its live figures to results/ros2/speed/.
