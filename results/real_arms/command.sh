#!/usr/bin/env bash
# Issue 37's real-arm figures as run on 2026-11-25, from the repository root (about 25 minutes on
# 2 cores): fetch the public UR10e logs, identify the twin (results/real_arms/twin.yaml,
# fidelity.md), record the quick corpus on it, train gbdt and stgnn_fixed for the stock_reduced
# profile (seed 42, W = 32, 10 epochs), commission on the joint-wise logs, monitor the rest.
set -euo pipefail
PY=${PY:-.venv/bin/python}
[ -d outputs/real_arms/logs ] || experiments/real_arms/fetch.sh
for f in outputs/real_arms/logs/*/*.csv; do   # which logs ingest, with which profile
  if out=$($PY -m robohealth_mj.ingest "$f" --out "outputs/real_arms/ingested/$(basename "$f" .csv)" 2>&1); then
    echo "0 $(basename "$f"): $(echo "$out" | grep 'sensing profile')"
  else echo "2 $(basename "$f"): $out"; fi
done > results/real_arms/ingest.txt
$PY experiments/real_arms/campaign.py --variants gbdt,stgnn_fixed --seed 42 --epochs 10
cp outputs/real_arms/twin/twin.yaml results/real_arms/twin.yaml
$PY experiments/real_arms/summarise.py > results/real_arms/sim_to_real.md
