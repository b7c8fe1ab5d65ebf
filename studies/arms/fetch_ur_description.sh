#!/usr/bin/env bash
# Copy UR's published arm parameters (Universal_Robots_ROS2_Description, BSD-3-Clause) into
# assets/<arm>/ur_description/, verbatim, with the licence. The files in the repository were made
# by this script from tag 2.4.5 (commit 2221ec0); rerun it to take a newer release.
#   studies/arms/fetch_ur_description.sh [git ref]
set -euo pipefail
ref="${1:-2.4.5}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
git clone --quiet --depth 1 --branch "$ref" \
    https://github.com/UniversalRobots/Universal_Robots_ROS2_Description.git "$work/ur"
for arm in ur3e ur5e ur10e ur16e ur20 ur30; do
    mkdir -p "$root/assets/$arm/ur_description"
    for f in default_kinematics physical_parameters joint_limits; do
        cp "$work/ur/config/$arm/$f.yaml" "$root/assets/$arm/ur_description/$f.yaml"
    done
done
{ echo "# Licence of the files under assets/*/ur_description/ (Universal_Robots_ROS2_Description $ref)"
  echo; echo '```'; cat "$work/ur/LICENSE"; echo '```'; } > "$root/assets/ur_description_licence.md"
echo "copied UR's parameter files ($ref) into $root/assets/*/ur_description/"
