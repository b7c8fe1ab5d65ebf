#!/usr/bin/env bash
# Fetch the public real UR10e logs into outputs/real_arms/logs/ (not into the repository: the
# source repository states no licence, so its data is not ours to redistribute; studies/real_arms/results/
# holds only figures measured on it). Source: github.com/shamilmamedov/dynamic_calibration
# (Innopolis University; the logs behind "Practical Aspects of Model-Based Collision Detection",
# Frontiers in Robotics and AI, 2020), folder dataset_ur10e/, at the commit the figures were
# measured on. About 30 MB.
#   studies/real_arms/fetch.sh [commit]
set -euo pipefail
ref="${1:-11af40e}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
dest="$root/outputs/real_arms/logs"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
git clone --quiet --filter=blob:none --no-checkout \
    https://github.com/shamilmamedov/dynamic_calibration.git "$work/dc"
git -C "$work/dc" checkout --quiet "$ref" -- dataset_ur10e
mkdir -p "$dest"
cp -r "$work/dc/dataset_ur10e/." "$dest/"
echo "fetched $(find "$dest" -name '*.csv' | wc -l) UR10e logs ($ref) into $dest"
