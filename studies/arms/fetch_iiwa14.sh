#!/usr/bin/env bash
# The community KUKA LBR iiwa 14 R820 description files write_iiwa14.py reads, at the cited commit.
set -euo pipefail
COMMIT=218d723f817c61314988833611effddc5333ca6c
BASE=https://raw.githubusercontent.com/lbr-stack/lbr_fri_ros2_stack/$COMMIT/lbr_description/urdf/iiwa14
mkdir -p outputs/iiwa14
for f in iiwa14_description.xacro joint_limits.yaml; do
  curl -fsSL "$BASE/$f" -o "outputs/iiwa14/$f"
done
