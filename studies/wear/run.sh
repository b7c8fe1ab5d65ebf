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
# the first lives' gbdt figures were measured with the severity booster's squared-error objective,
# the default until 2026-11-26 (now `levels`, chosen on the standard corpus below; on lives after)
SQ=(--override model.severity_objective=regression)
$PY studies/wear/campaign.py --variant gbdt --labels last "${SQ[@]}"
$PY studies/wear/campaign.py --variant stgnn_fixed --labels last --estimators trend
$PY studies/wear/campaign.py --variant gbdt --train-also 'outputs/corpus/standard/train_*' \
    --name gbdt_standard+lives_last_s42 "${SQ[@]}"
# the severity booster as `levels` (the default since 2026-11-26) on lives: standard + lives on
# three seeds, and lives alone on seed 42 (~20 min each on 2 cores); the corpus's val_lives (added
# 2026-11-26, ~4 min) are where these runs tune the warning
for s in 42 43 44; do
  $PY studies/wear/campaign.py --variant gbdt --seed $s \
      --train-also 'outputs/corpus/standard/train_*' --name gbdt_standard+lives_levels_s$s
done
$PY studies/wear/campaign.py --variant gbdt --labels last --name gbdt_lives_levels_s42
$PY studies/wear/summarise.py outputs/lives/gbdt_last_s42/lives.json \
    outputs/lives/stgnn_fixed_last_s42/lives.json \
    'outputs/lives/gbdt_standard+lives_last_s42/lives.json' \
    outputs/lives/gbdt_lives_levels_s42/lives.json \
    'outputs/lives/gbdt_standard+lives_levels_s42/lives.json' \
    'outputs/lives/gbdt_standard+lives_levels_s43/lives.json' \
    'outputs/lives/gbdt_standard+lives_levels_s44/lives.json' --out studies/wear/results
# the trend's window (sessions in its line) on the validation lives
$PY studies/wear/trend_window.py outputs/lives/gbdt_standard+lives_levels_s4{2,3,4} \
    > studies/wear/results/trend_window.md
$PY -m robohealth_mj.report --lives 'outputs/lives/gbdt_standard+lives_levels_s42/lives.json' \
    --out studies/wear/results/figures
for run in gbdt_last_s42 stgnn_fixed_last_s42 gbdt_standard+lives_last_s42 gbdt_lives_levels_s42 \
    gbdt_standard+lives_levels_s42 gbdt_standard+lives_levels_s43 gbdt_standard+lives_levels_s44; do
  cp "outputs/lives/$run/lives.json" "studies/wear/results/lives_$run.json"
  cp "outputs/lives/$run/calibration.json" "studies/wear/results/calibration_$run.json"
done
# the severity head on the standard held-out session: trained and scored with each label rule
for trained in last time_weighted; do
  $PY -m robohealth_mj.train variant=gbdt seed=42 window=32 labels=$trained \
      model.severity_objective=regression \
      'data.train=[outputs/corpus/standard/train_*]' \
      data.evaluate.heldout=outputs/corpus/standard/heldout_seed900 data.evaluate.probe=null \
      out_dir=outputs/severity_labels/gbdt_$trained
  for rule in last majority time_weighted; do
    $PY -m robohealth_mj.evaluate ckpt=outputs/severity_labels/gbdt_$trained/best.ckpt \
        data=outputs/corpus/standard/heldout_seed900 labels=$rule \
        out=outputs/severity_labels/gbdt_$trained/eval_heldout_as_$rule
  done
done
$PY studies/wear/severity_strata.py outputs/severity_labels/gbdt_last/best.ckpt \
    outputs/corpus/standard/heldout_seed900 > studies/wear/results/severity_strata_gbdt_standard.json
# the severity head's formulation (2026-11-26): candidates on the validation split of the `last`
# checkpoint; then each objective refit on three seeds' checkpoints (seed 42 above; 43 and 44
# trained with the default, now `levels`) and scored on the held-out session (~25 min)
$PY studies/wear/severity_variants.py outputs/severity_labels/gbdt_last/best.ckpt \
    > studies/wear/results/severity_objective/variants_s42.jsonl
for s in 43 44; do
  $PY -m robohealth_mj.train variant=gbdt seed=$s window=32 labels=last \
      'data.train=[outputs/corpus/standard/train_*]' \
      data.evaluate.heldout=outputs/corpus/standard/heldout_seed900 data.evaluate.probe=null \
      out_dir=outputs/severity_objective/gbdt_levels_s$s
done
declare -A CKPT=([42]=outputs/severity_labels/gbdt_last/best.ckpt
                 [43]=outputs/severity_objective/gbdt_levels_s43/best.ckpt
                 [44]=outputs/severity_objective/gbdt_levels_s44/best.ckpt)
for s in 42 43 44; do
  $PY studies/wear/severity_objective.py "${CKPT[$s]}" --out outputs/severity_objective/s$s \
      > outputs/severity_objective/s$s.jsonl
  cp outputs/severity_objective/s$s.jsonl studies/wear/results/severity_objective/
  for o in regression regression_l1 levels; do
    $PY -m robohealth_mj.evaluate ckpt=outputs/severity_objective/s$s/$o/best.ckpt \
        data=outputs/corpus/standard/heldout_seed900 \
        out=outputs/severity_objective/s$s/$o/eval_heldout
  done
done
$PY studies/wear/summarise_severity.py outputs/severity_objective --seeds 42,43,44 \
    > studies/wear/results/severity_objective/table.md
$PY studies/wear/severity_strata.py outputs/severity_objective/s42/levels/best.ckpt \
    outputs/corpus/standard/heldout_seed900 > studies/wear/results/severity_strata_gbdt_levels_standard.json
