#!/usr/bin/env bash
# Re-makes the benchmark files of this study, one after the other on an otherwise idle machine.
# Run from the repository root after `make run` (quick corpus); --headline needs the standard corpus.
set -euo pipefail
PY=${PY:-.venv/bin/python}
OUT=studies/benchmarks/results
$PY -m robohealth_mj.bench sim | tee $OUT/bench_sim.txt
$PY -m robohealth_mj.bench models | tee $OUT/bench_models.txt
$PY -m robohealth_mj.bench infer | tee $OUT/bench_infer.txt
$PY -m robohealth_mj.bench train | tee $OUT/bench_train.txt
$PY -m robohealth_mj.bench train --headline | tee $OUT/bench_train_headline.txt
