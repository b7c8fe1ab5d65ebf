#!/usr/bin/env bash
# Re-makes the ready models the wheel ships (ready_models/: full, stock, ur_driver), their model
# cards and the sample log, from a fresh clone, in one command: bash studies/ready_models/run.sh
# (about 40 minutes on 2 cores: the corpus's training, held-out and probe sessions, three runs).
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
CORPUS=outputs/corpus/standard
OUT=outputs/ready
# The standard corpus's training sessions, held-out session (seed 900) and high-payload probe;
# its other roles (unseen arms and programs) are the studies' and are not needed here.
$PY -m robohealth_mj.corpus corpus=standard progress=false '~corpus.probe_unseen_arms' \
  '~corpus.probe_nominal_arms' '~corpus.healthy_unseen_arms' '~corpus.probe_unseen_program' \
  '~corpus.val_unseen_program'
# One run per profile at the headline's operating window (W = 32), seed 42: the full sensor
# package's headline (anomaly_residual), and for the channels a controller reports (stock: UR's
# RTDE; ur_driver: the UR ROS 2 driver's topics) stgnn_fixed, the stock study's headline.
for spec in "full anomaly_residual full" "stock stgnn_fixed stock" "ur_driver stgnn_fixed ur_driver"; do
  set -- $spec
  $PY -m robohealth_mj.train variant="$2" sensing="$3" window=32 seed=42 trainer.progress=false \
    out_dir="$OUT/$1" skip_done=false
  $PY -m robohealth_mj.export ckpt="$OUT/$1/best.ckpt" out="$OUT/$1/model.onnx"
done
$PY studies/ready_models/make_ready.py "$OUT" "$CORPUS"   # -> ready_models/*.onnx, *.md, sample
