#!/usr/bin/env bash
# The stock-arm results (issue 18), from a fresh clone; CORPUS names the corpus directory.
set -euo pipefail
CORPUS=${CORPUS:-outputs/corpus/standard}
PY=.venv/bin/python
$PY -m robohealth_mj.corpus corpus=standard progress=false          # with the unseen-arm roles
CORPUS=$CORPUS bash results/thesis_physics/command.sh stock matrix_w32   # 3 seeds each, W = 32
$PY results/stock/compare.py                                        # -> stock_vs_full.md
$PY results/stock/unseen_arms.py "$CORPUS"                          # -> unseen_arms.md
bash results/stock/alarms.sh "$CORPUS" && $PY results/stock/unseen_arms.py "$CORPUS"
