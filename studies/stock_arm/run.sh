#!/usr/bin/env bash
# The stock-arm results (issue 18), from a fresh clone; CORPUS names the corpus directory.
set -euo pipefail
CORPUS=${CORPUS:-outputs/corpus/standard}
PY=.venv/bin/python
$PY -m robohealth_mj.corpus corpus=standard progress=false          # with the unseen-arm/program roles
CORPUS=$CORPUS bash studies/thesis_physics/run.sh stock matrix_w32   # 3 seeds each, W = 32
$PY studies/stock_arm/compare.py                                        # -> stock_vs_full.md
$PY studies/stock_arm/unseen_arms.py "$CORPUS"                          # -> unseen_arms.md
bash studies/stock_arm/run_alarms.sh "$CORPUS" && $PY studies/stock_arm/unseen_arms.py "$CORPUS"
# An unseen program: ten minutes of its healthy running to commission on, then the table.
$PY -m robohealth_mj.record seed=950 faults=none session.duration_s=600 \
  'curriculum.families=[pick_place]' 'curriculum.speed_scales=[0.6,1.0,1.5]' \
  'curriculum.payload_scales=[0.5,1.0,1.6]' session.progress=false \
  session.out_dir="$CORPUS/healthy_program_seed950"
# The operating-point recipe, chosen on the program's validation session (seed 932), then the
# probe sessions (930-931) with it, and where the headline still loses accuracy there.
$PY studies/stock_arm/operating_point_recipe.py "$CORPUS"               # -> operating_point_recipe.md
$PY studies/stock_arm/unseen_program.py "$CORPUS"                       # -> unseen_program.md
$PY studies/stock_arm/program_strata.py "$CORPUS" > studies/stock_arm/results/program_strata.md
# Placement self-calibration (retrofit harness, W = 32, seed 42): models trained under 256 drawn
# placements, models trained on each test placement (the references), then commissioning on ten
# healthy minutes of the nominal arm.
$PY -m robohealth_mj.record seed=940 faults=none session.duration_s=600 session.progress=false \
  session.out_dir="$CORPUS/healthy_nominal_seed940"
H="graph=harness sensing=retrofit variant=anomaly_residual model.anomaly_scores=energy window=32"
D="data.train=[$CORPUS/train_*] data.evaluate.heldout=$CORPUS/heldout_seed900"
P="$H $D data.evaluate.probe=null trainer.placements=256 trainer.epochs=40 trainer.patience=8"
P="$P threads=1"
S=outputs/selfcal
# The pool model's design (pool_design.md): the earlier dense-edge model, then the placement told
# to message passing, the head's joint scores and the sensor nodes, alone and together; the
# chosen one (+experiment=self_calibrating, the same settings); the same told C with a fit's errors.
# shellcheck disable=SC2086
{
  $PY -m robohealth_mj.train $P out_dir=$S/pool256_e40
  $PY -m robohealth_mj.train $P model.coupled_edges=true out_dir=$S/pool256_e40_edges
  $PY -m robohealth_mj.train $P model.anomaly_joint_scores=true out_dir=$S/pool256_e40_joint
  $PY -m robohealth_mj.train $P model.coupled_edges=true model.anomaly_joint_scores=true \
    out_dir=$S/pool256_e40_edges_joint
  $PY -m robohealth_mj.train $P model.anomaly_joint_scores=true model.placement_embedding=true \
    out_dir=$S/pool256_e40_joint_placed
  $PY -m robohealth_mj.train +experiment=self_calibrating sensing=retrofit $D \
    data.evaluate.probe=null threads=1 out_dir=$S/pool256_e40_edges_joint_placed
  $PY -m robohealth_mj.train +experiment=self_calibrating sensing=retrofit $D \
    data.evaluate.probe=null threads=1 trainer.placement_noise=0.3 \
    out_dir=$S/pool256_e40_edges_joint_placed_noise03
}
CORPUS=$CORPUS THREADS=2 $PY studies/stock_arm/pool_design.py dense=$S/pool256_e40/best.ckpt \
  edges=$S/pool256_e40_edges/best.ckpt joint_scores=$S/pool256_e40_joint/best.ckpt \
  edges+joint_scores=$S/pool256_e40_edges_joint/best.ckpt \
  joint_scores+placement_embedding=$S/pool256_e40_joint_placed/best.ckpt \
  edges+joint_scores+placement_embedding=$S/pool256_e40_edges_joint_placed/best.ckpt \
  edges+joint_scores+placement_embedding+noise_0.3=$S/pool256_e40_edges_joint_placed_noise03/best.ckpt \
  > studies/stock_arm/results/pool_design.md
# shellcheck disable=SC2086
$PY -m robohealth_mj.train -m hydra/launcher=local hydra.launcher.n_jobs=2 threads=1 \
  hydra.sweep.dir=outputs/thesis_physics $D data.evaluate.probe=$CORPUS/probe_payload_high_seed901 \
  +experiment=placements sensing=retrofit variant=anomaly_residual model.anomaly_scores=energy \
  graph.coupling_sensors=4 graph.coupling_seed=2,5,21,22,23
CORPUS=$CORPUS $PY studies/stock_arm/self_calibration.py $S/pool256_e40_edges_joint_placed/best.ckpt \
  outputs/thesis_physics/harness/retrofit/C0/anomaly_residual/w32/seed42/best.ckpt \
  > studies/stock_arm/results/self_calibration.md
CORPUS=$CORPUS $PY studies/stock_arm/self_calibration.py $S/pool256_e40/best.ckpt \
  > studies/stock_arm/results/self_calibration_dense_pool.md
# A second seed of the chosen pool model and of the trained-on-placement references.
# shellcheck disable=SC2086
$PY -m robohealth_mj.train +experiment=self_calibrating sensing=retrofit $D seed=43 \
  data.evaluate.probe=null threads=1 out_dir=$S/self_calibrating_seed43
# shellcheck disable=SC2086
$PY -m robohealth_mj.train -m hydra/launcher=local hydra.launcher.n_jobs=2 threads=1 \
  hydra.sweep.dir=outputs/thesis_physics $D data.evaluate.probe=$CORPUS/probe_payload_high_seed901 \
  +experiment=placements sensing=retrofit variant=anomaly_residual model.anomaly_scores=energy \
  graph.coupling_sensors=4 graph.coupling_seed=2,5,21,22,23 seed=43
CORPUS=$CORPUS $PY studies/stock_arm/self_calibration.py $S/self_calibrating_seed43/best.ckpt \
  outputs/thesis_physics/harness/retrofit/C0/anomaly_residual/w32/seed43/best.ckpt \
  > studies/stock_arm/results/self_calibration_seed43.md
# Ablation: a model trained from scratch on the placement the motion fit found (the rest as the
# trained-on-placement references), scored on the held-out session mixed by the true placement.
CORPUS=$CORPUS $PY studies/stock_arm/self_calibration_retrain.py estimate outputs/selfcal/pool256_e40/best.ckpt
for s in 2 5 21 22 23; do
  # shellcheck disable=SC2086
  $PY -m robohealth_mj.train sensing=retrofit threads=1 $D data.evaluate.probe=null \
    +experiment=placements variant=anomaly_residual model.anomaly_scores=energy \
    graph.coupling_file=outputs/selfcal/estimated/seed$s.json out_dir=outputs/selfcal/retrained/seed$s
done
CORPUS=$CORPUS $PY studies/stock_arm/self_calibration_retrain.py > studies/stock_arm/results/self_calibration_retrain.md
