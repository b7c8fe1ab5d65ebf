#!/usr/bin/env bash
# Wear over weeks (issues 39 and 68). Parts, in order (default: all):
#   corpus    the lives corpus (~25 min on 2 cores, with issue 68's fresh lives) and the standard
#             corpus's training and held-out roles (~20 min)
#   planner   issue 68: gbdt on the standard corpus + training lives at three seeds (~12 min each),
#             every index model, chosen on the validation lives, figures on held-out and fresh lives
#   severity  the severity head on the standard held-out session (issue 39; ~45 min)
# The issue-39 campaign tables (results/lives.md, lives_*.json, calibration_*.json, trend_window.md)
# were made by the campaign as it stood then: `git show 300430b:studies/wear/run.sh`.
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
PARTS=${*:-corpus planner severity}
part() { [[ " $PARTS " == *" $1 "* ]]; }
if part corpus; then
  $PY -m robohealth_mj.corpus corpus=lives
  $PY -m robohealth_mj.corpus '~corpus.probe_payload_high' '~corpus.probe_unseen_arms' \
      '~corpus.probe_nominal_arms' '~corpus.healthy_unseen_arms' '~corpus.probe_unseen_program' \
      '~corpus.val_unseen_program'
fi
if part planner; then
  for s in 42 43 44; do
    $PY studies/wear/campaign.py --variant gbdt --seed $s \
        --train-also 'outputs/corpus/standard/train_*' --name planner_s$s
  done
  # stiffness loss at the shoulder pan moves its channels 2 healthy spreads at severity 0.3
  # (severity_channels.md): the MAE is also given without it
  $PY studies/wear/planner_tables.py outputs/lives/planner_s{42,43,44}/lives.json \
      --unobservable struct_weaken:shoulder_pan > studies/wear/results/planner.md
  # how far one channel may pull the signatures' severity read, chosen on the validation lives
  $PY studies/wear/outlier_grid.py outputs/lives/planner_s{42,43,44} \
      > studies/wear/results/outlier_grid.md
  # the wearing joint's severity: the index against the channel each mode acts on
  $PY studies/wear/severity_channels.py outputs/lives/planner_s42 \
      > studies/wear/results/severity_channels.md
  # a gap against a softer drive on a loaded joint: one day cannot tell them, the days' loads can
  $PY studies/wear/load_dependence.py > studies/wear/results/load_dependence.md
  $PY -m robohealth_mj.report --lives outputs/lives/planner_s42/lives.json \
      --out outputs/lives/planner_s42/figures
  cp outputs/lives/planner_s42/figures/life_fresh_lives_00_seed6000.png \
      studies/wear/results/figures/signature_s42_fresh_backlash_wrist1.png  # the first pass's: planner_s42_*
fi
part severity || exit 0
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
