#!/usr/bin/env bash
# Which ignore_type_information default lets the monitor meet a real ROS 2 node on Fast DDS (the
# default middleware of ROS 2 Humble, Jazzy and later): rclpy from the ros-rclpy wheels, in their
# own venv (they install a .pth hook), against the project's Cyclone participant, both ways, each
# setting. Runs inside a network namespace of its own with loopback only (unshare -n, as root), so
# Fast DDS's multicast discovery never leaves the machine.
#   bash studies/ros2/type_information.sh > studies/ros2/results/type_information.txt
set -euo pipefail
cd "$(dirname "$0")/../.."
ROS=outputs/ros_venv
if [ ! -x $ROS/bin/python ]; then
  python3 -m venv $ROS
  $ROS/bin/pip install -q 'ros-rclpy[fastrtps]' ros-sensor-msgs ros-diagnostic-msgs
fi
PY=${PY:-.venv/bin/python}
HERE=studies/ros2
unshare -n bash -s <<SH 2>&1 | grep -v "invalid type object"
set -e
ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo
for ignore in false true; do
  $PY $HERE/cyclone_peer.py read \$ignore 7 & $ROS/bin/python $HERE/fastdds_peer.py publish 60; wait
  $ROS/bin/python $HERE/fastdds_peer.py subscribe 8 & $PY $HERE/cyclone_peer.py write \$ignore 60; wait
done
SH
