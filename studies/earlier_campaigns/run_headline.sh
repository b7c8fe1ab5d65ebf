#!/usr/bin/env bash
# The models issue's campaign on the standard corpus (W = 32, seeds 42-44), two jobs of one thread
# each, then the report. Run from the repository root after `python -m robohealth_mj.corpus`.
set -euo pipefail
PY=${PY:-.venv/bin/python}
$PY -m robohealth_mj.train -m +experiment=headline hydra/launcher=local threads=1
# Harness rows over the three seeds.
$PY -m robohealth_mj.train -m +experiment=headline hydra/launcher=local threads=1 \
  graph=harness variant=gbdt,stgnn_fixed,anomaly_residual seed=42,43,44
$PY -m robohealth_mj.report outputs/campaign_headline
