#!/usr/bin/env bash
# Kinova's Gen3 7-DoF description that write_gen3.py reads, at the cited commit.
set -euo pipefail
COMMIT=1fdbef345954b326627dc3792981e18e2221450b
mkdir -p outputs/gen3
curl -fsSL "https://raw.githubusercontent.com/Kinovarobotics/ros2_kortex/$COMMIT/kortex_description/arms/gen3/7dof/urdf/gen3_macro.xacro" \
  -o outputs/gen3/gen3_macro.xacro
