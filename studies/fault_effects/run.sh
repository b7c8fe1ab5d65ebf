#!/usr/bin/env bash
# Physics fault effect sizes on every channel (schema 2.0): 6 faults x 3 joints x 3 severities, 30 s.
set -euo pipefail
PY=${PY:-.venv/bin/python}
$PY -m robohealth_mj.effects --markdown --json studies/fault_effects/results/physics.json > studies/fault_effects/results/physics.md
