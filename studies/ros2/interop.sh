#!/usr/bin/env bash
# The monitor and a real ROS 2 node with default settings on both sides (tests/ros2/test_interop.py,
# run longer): rclpy on Fast DDS publishes /joint_states for two arms as the UR driver does (its
# joint names, each arm's tf_prefix, alphabetical order) at 20 Hz for 20 s, in a network namespace
# with loopback only; the monitor (ros2.layout=ur_driver, a joint_states model) diagnoses them and
# the node times each diagnosis from its own publish of the tick. Three runs.
#   bash studies/ros2/interop.sh > studies/ros2/results/interop.txt
set -euo pipefail  # ROBOHEALTH_TEST_CACHE=DIR reuses the test fixtures' trained model
cd "$(dirname "$0")/../.."
echo "# bash studies/ros2/interop.sh ($(nproc) cores, $(date -u +%Y-%m-%d))"
for run in 1 2 3; do
  ROBOHEALTH_INTEROP_TICKS=400 .venv/bin/python -m pytest -q -s -p no:cacheprovider \
    tests/ros2/test_interop.py 2>&1 | grep -E "diagnosis latency|passed|failed" | tr '\n' ' '
  echo "(run $run)"
done
