#!/usr/bin/env bash
# UFACTORY's xArm7 description files that write_xarm7.py reads, at the cited commit (branch humble).
set -euo pipefail
COMMIT=5109131e7870c7d6e1075042d531e659d072cdb0
BASE=https://raw.githubusercontent.com/xArm-Developer/xarm_ros2/$COMMIT/xarm_description
mkdir -p outputs/xarm7
curl -fsSL "$BASE/config/kinematics/default/xarm7_default_kinematics.yaml" -o outputs/xarm7/xarm7_default_kinematics.yaml
curl -fsSL "$BASE/config/link_inertial/xarm7_type7_HT_BR2.yaml" -o outputs/xarm7/xarm7_type7_HT_BR2.yaml
curl -fsSL "$BASE/urdf/xarm7/xarm7.urdf.xacro" -o outputs/xarm7/xarm7.urdf.xacro
