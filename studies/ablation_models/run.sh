#!/usr/bin/env bash
# The figure of this study from its committed table (the rows themselves are one `train` run each,
# with the overrides listed in README.md, at the commit that added the table).
set -euo pipefail
PY=${PY:-.venv/bin/python}
$PY studies/ablation_models/figure.py
