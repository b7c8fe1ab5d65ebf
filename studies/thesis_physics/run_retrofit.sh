#!/usr/bin/env bash
# The campaign issue's retrofit profile, first measurement: harness (default C0) + sensing=retrofit,
# gbdt and anomaly_residual, seed 42, W = 32, 20 epochs, side by side on one thread each; training
# sessions with healthy segment starts; the standard held-out session.
set -euo pipefail
PY=${PY:-.venv/bin/python}
for v in anomaly_residual gbdt; do
  $PY -m robohealth_mj.train variant=$v graph=harness sensing=retrofit seed=42 window=32 \
    threads=1 trainer.progress=false '~data.evaluate.probe' out_dir=outputs/retrofit/${v}_seed42 &
done
wait
