#!/usr/bin/env bash
# Wear over weeks (issue 39): the lives corpus, the window models trained on it, the health index,
# RUL and wear warnings on held-out lives, and the figures. About 20 min (corpus) + 15 min per
# model on 2 cores. Outputs in outputs/lives/<run>/ (lives.json, calibration.json); tables here.
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
$PY -m robohealth_mj.corpus corpus=lives
$PY experiments/lives/campaign.py --variant gbdt --labels last
$PY experiments/lives/campaign.py --variant stgnn_fixed --labels last --estimators trend
$PY experiments/lives/summarise.py outputs/lives/gbdt_last_s42/lives.json \
    outputs/lives/stgnn_fixed_last_s42/lives.json --out results/lives
$PY -m robohealth_mj.report --lives outputs/lives/gbdt_last_s42/lives.json --out results/lives/figures
cp outputs/lives/gbdt_last_s42/lives.json results/lives/lives_gbdt.json
cp outputs/lives/gbdt_last_s42/calibration.json results/lives/calibration_gbdt.json
cp outputs/lives/stgnn_fixed_last_s42/lives.json results/lives/lives_stgnn_fixed.json
cp outputs/lives/stgnn_fixed_last_s42/calibration.json results/lives/calibration_stgnn_fixed.json
