#!/usr/bin/env bash
# The stock-arm results (issue 18), from a fresh clone; CORPUS names the corpus directory.
set -euo pipefail
CORPUS=${CORPUS:-outputs/corpus/standard}
PY=.venv/bin/python
$PY -m robohealth_mj.corpus corpus=standard progress=false          # with the unseen-arm/program roles
CORPUS=$CORPUS bash results/thesis_physics/command.sh stock matrix_w32   # 3 seeds each, W = 32
$PY results/stock/compare.py                                        # -> stock_vs_full.md
$PY results/stock/unseen_arms.py "$CORPUS"                          # -> unseen_arms.md
bash results/stock/alarms.sh "$CORPUS" && $PY results/stock/unseen_arms.py "$CORPUS"
# An unseen program: ten minutes of its healthy running to commission on, then the table.
$PY -m robohealth_mj.record seed=950 faults=none session.duration_s=600 \
  'curriculum.families=[pick_place]' 'curriculum.speed_scales=[0.6,1.0,1.5]' \
  'curriculum.payload_scales=[0.5,1.0,1.6]' session.progress=false \
  session.out_dir="$CORPUS/healthy_program_seed950"
# The operating-point recipe, chosen on the program's validation session (seed 932), then the
# probe sessions (930-931) with it, and where the headline still loses accuracy there.
$PY results/stock/operating_point_recipe.py "$CORPUS"               # -> operating_point_recipe.md
$PY results/stock/unseen_program.py "$CORPUS"                       # -> unseen_program.md
$PY results/stock/program_strata.py "$CORPUS" > results/stock/program_strata.md
# Placement self-calibration (retrofit harness, W = 32, seed 42): a model trained under 256 drawn
# placements, models trained on each test placement (the references), then commissioning on ten
# healthy minutes of the nominal arm.
$PY -m robohealth_mj.record seed=940 faults=none session.duration_s=600 session.progress=false \
  session.out_dir="$CORPUS/healthy_nominal_seed940"
H="graph=harness sensing=retrofit variant=anomaly_residual model.anomaly_scores=energy window=32"
D="data.train=[$CORPUS/train_*] data.evaluate.heldout=$CORPUS/heldout_seed900"
# shellcheck disable=SC2086
$PY -m robohealth_mj.train $H $D data.evaluate.probe=null trainer.placements=256 \
  trainer.epochs=40 trainer.patience=8 trainer.threads=1 out_dir=outputs/selfcal/pool256_e40
# shellcheck disable=SC2086
$PY -m robohealth_mj.train -m hydra/launcher=local hydra.launcher.n_jobs=2 trainer.threads=1 \
  hydra.sweep.dir=outputs/thesis_physics $D data.evaluate.probe=$CORPUS/probe_payload_high_seed901 \
  +experiment=placements sensing=retrofit variant=anomaly_residual model.anomaly_scores=energy \
  graph.coupling_sensors=4 graph.coupling_seed=2,5,21,22,23
CORPUS=$CORPUS $PY results/stock/self_calibration.py outputs/selfcal/pool256_e40/best.ckpt \
  outputs/thesis_physics/harness/retrofit/C0/anomaly_residual/w32/seed42/best.ckpt \
  > results/stock/self_calibration.md
# Ablation: a model trained from scratch on the placement the motion fit found (the rest as the
# trained-on-placement references), scored on the held-out session mixed by the true placement.
CORPUS=$CORPUS $PY results/stock/self_calibration_retrain.py estimate outputs/selfcal/pool256_e40/best.ckpt
for s in 2 5 21 22 23; do
  # shellcheck disable=SC2086
  $PY -m robohealth_mj.train sensing=retrofit trainer.threads=1 $D data.evaluate.probe=null \
    +experiment=placements variant=anomaly_residual model.anomaly_scores=energy \
    graph.coupling_file=outputs/selfcal/estimated/seed$s.json out_dir=outputs/selfcal/retrained/seed$s
done
CORPUS=$CORPUS $PY results/stock/self_calibration_retrain.py > results/stock/self_calibration_retrain.md
