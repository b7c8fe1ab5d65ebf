#!/usr/bin/env bash
# Wear over weeks (issue 39): the lives corpus, window models trained on it (and on the standard
# corpus beside it), the health index, RUL and wear warnings on held-out lives, the figures, and
# the severity head on the standard held-out session under each window-label rule. On 2 cores:
# ~20 min (lives corpus), ~20 min (standard corpus, two roles), 10-25 min per model.
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
$PY -m robohealth_mj.corpus corpus=lives
$PY -m robohealth_mj.corpus '~corpus.probe_payload_high' '~corpus.probe_unseen_arms' \
    '~corpus.probe_nominal_arms' '~corpus.healthy_unseen_arms' '~corpus.probe_unseen_program' \
    '~corpus.val_unseen_program'
$PY experiments/lives/campaign.py --variant gbdt --labels last
$PY experiments/lives/campaign.py --variant stgnn_fixed --labels last --estimators trend
$PY experiments/lives/campaign.py --variant gbdt --train-also 'outputs/corpus/standard/train_*' \
    --name gbdt_standard+lives_last_s42
$PY experiments/lives/summarise.py outputs/lives/gbdt_last_s42/lives.json \
    outputs/lives/stgnn_fixed_last_s42/lives.json \
    'outputs/lives/gbdt_standard+lives_last_s42/lives.json' --out results/lives
$PY -m robohealth_mj.report --lives 'outputs/lives/gbdt_standard+lives_last_s42/lives.json' \
    --out results/lives/figures
for run in gbdt_last_s42 stgnn_fixed_last_s42 gbdt_standard+lives_last_s42; do
  cp "outputs/lives/$run/lives.json" "results/lives/lives_$run.json"
  cp "outputs/lives/$run/calibration.json" "results/lives/calibration_$run.json"
done
# the severity head on the standard held-out session: trained and scored with each label rule
for trained in last time_weighted; do
  $PY -m robohealth_mj.train variant=gbdt seed=42 window=32 labels=$trained \
      'data.train=[outputs/corpus/standard/train_*]' \
      data.evaluate.heldout=outputs/corpus/standard/heldout_seed900 data.evaluate.probe=null \
      out_dir=outputs/severity_labels/gbdt_$trained
  for rule in last majority time_weighted; do
    $PY -m robohealth_mj.evaluate ckpt=outputs/severity_labels/gbdt_$trained/best.ckpt \
        data=outputs/corpus/standard/heldout_seed900 labels=$rule \
        out=outputs/severity_labels/gbdt_$trained/eval_heldout_as_$rule
  done
done
$PY experiments/lives/severity_strata.py outputs/severity_labels/gbdt_last/best.ckpt \
    outputs/corpus/standard/heldout_seed900 > results/lives/severity_strata_gbdt_standard.json
