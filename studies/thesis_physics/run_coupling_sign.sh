#!/usr/bin/env bash
# The campaign issue's sign constraint, first measurement: the harness model (default C0) with the
# thesis's signed sensor scores against the energy scores that pin C's sign; seeds 42 and 43,
# W = 32, 20 epochs, one thread each, two side by side; training sessions with healthy segment starts.
set -euo pipefail
PY=${PY:-.venv/bin/python}
for seed in 42 43; do
  for sc in signed energy; do
    $PY -m robohealth_mj.train variant=anomaly_residual graph=harness seed=$seed window=32 \
      model.anomaly_scores=$sc threads=1 trainer.progress=false '~data.evaluate.probe' \
      out_dir=outputs/coupling_sign/harness_${sc}_seed$seed &
  done
  wait
done
