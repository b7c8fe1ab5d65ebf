#!/usr/bin/env bash
# Why the learned coupling's shoulder_pan row misses C0 (results.md): R^2 of each package from each
# joint's state on healthy ticks of four standard training sessions, and per-row corr(C, C0).
set -euo pipefail
PY=${PY:-.venv/bin/python}
$PY studies/thesis_physics/measure_identifiability.py 'outputs/corpus/standard/train_0[0-3]*/graphs.jsonl' \
  outputs/thesis_physics/harness/full/C0/anomaly_residual/w32/seed42 \
  outputs/thesis_physics/harness/retrofit/C0/anomaly_residual/w32/seed42 > studies/thesis_physics/results/identifiability/results.md
