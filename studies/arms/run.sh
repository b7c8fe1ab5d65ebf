#!/usr/bin/env bash
# Issue 36's cross-arm experiment as run on 2026-11-26, from the repository root: the networks at
# 30 epochs on a lent GPU, everything else on 2 cores here (about 2 hours).
#   1. each arm's corpus (conf/corpus/arms.yaml: eight training sessions, a held-out one, ten
#      healthy minutes to commission on, a healthy hour to count false alarms on);
#   2. on the lent GPU: studies/arms/gpu_networks.sh (stgnn_fixed and the headline
#      anomaly_residual, own and leave-one-arm-out, seeds 42-44, full and stock sensing; the run
#      directories unpacked here under outputs/campaign_arms);
#   3. here: gbdt (leave-one-arm-out seeds 42-44, own models seed 42; its severity booster off, as
#      the experiment scores class and joint and that booster changes neither), every network
#      scored again on this machine's recording of the held-out session, each leave-one-arm-out
#      model commissioned on the unseen arm's ten healthy minutes and scored, each commissioned
#      network's alarms counted over the unseen arm's healthy hour;
#   4. the tables (studies/arms/results/table_full_split_by_run.md, table_stock_split_by_run.md) and the
#      recorder per arm;
#   5. the leave-one-arm-out models again on the fixed split, seed 42;
#   6. three seeds on the fixed split, the stock profile with gbdt, and the stricter operating
#      point (studies/arms/results/table_full.md, table_stock.md, table_full_hr0.99.md);
#   7. (2026-11-27) gbdt's own models at seeds 43-44: full sensing on the UR5e, UR10e and UR16e
#      (the UR3e had them), the stock profile on every arm; the tables again.
# The 10-epoch campaign of 2026-11-25 (own models seed 42, networks 10 epochs, full sensing) is
# studies/arms/results/table_full_e10.md; its relative-channel ablation studies/arms/results/raw_channels.md.
set -euo pipefail
PY=${PY:-.venv/bin/python}
for arm in ur5e ur10e ur3e ur16e; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm \
    "record_overrides=[\"arm=$arm\"]" progress=false
done
# step 2 runs on the GPU machine; then, here:
#   tar -xzf campaign_arms_gpu.tgz   (outputs/campaign_arms/{full,stock}/{own,loao}/<arm>/...)
C="$PY studies/arms/campaign.py"
$C --variants gbdt --seeds 42,43,44 --override model.severity=false --stages loao \
  --steps train,commission
$C --variants gbdt --seeds 42 --override model.severity=false --stages own --steps train
$C --variants stgnn_fixed,anomaly_residual --steps rescore,commission,alarms
$C --variants stgnn_fixed --sensing stock --steps rescore,commission
$C --variants stgnn_fixed --sensing stock --steps alarms
# The tables of this campaign, whose leave-one-arm-out models validated on a split that leaked
# across arms (studies/arms/README.md): kept as *_split_by_run.md. (Steps 2-3 ran at commit e37b51a; on
# today's code their leave-one-arm-out trainings split by session, as step 5 does.)
$PY studies/arms/summarise.py --sensing full > studies/arms/results/table_full_split_by_run.md
$PY studies/arms/summarise.py --sensing stock > studies/arms/results/table_stock_split_by_run.md
$PY studies/arms/summarise.py --sensing full --seeds 42 \
  > studies/arms/results/table_full_split_by_run_seed42.md
# 5. (2026-11-26, after the split was fixed: a session recorded on several arms is one session)
#    the leave-one-arm-out models again, here on 2 cores, in their own campaign root, beside the
#    same own models (unchanged: one arm's corpus splits exactly as before):
G="$C --out outputs/campaign_arms_grouped --stages loao"
mkdir -p outputs/campaign_arms_grouped/full
ln -sfn ../../campaign_arms/full/own outputs/campaign_arms_grouped/full/own
# (seed 43 of the networks as far as the session's time went: stgnn_fixed on the UR3e, the
# headline on the UR5e)
$G --variants gbdt --seeds 42,43 --override model.severity=false --steps train,commission
$G --variants stgnn_fixed,anomaly_residual --seeds 42 --epochs 30 --steps train,commission,alarms
$G --variants stgnn_fixed --seeds 43 --epochs 30 --arms ur3e --steps train,commission,alarms
$G --variants anomaly_residual --seeds 43 --epochs 30 --arms ur5e --steps train,commission,alarms
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_grouped --seeds 42 \
  > studies/arms/results/table_full_seed42.md
# 6. (2026-11-26, a later session) three seeds on the fixed split. The networks' missing seeds
#    (full: seed 44, and 43 where step 5 lacks it) and the stock profile's stgnn_fixed, seeds
#    42-44, as a job list:
{ for a in ur5e ur10e ur16e; do echo "full loao $a stgnn_fixed 43"; done
  for a in ur3e ur10e ur16e; do echo "full loao $a anomaly_residual 43"; done
  for a in ur3e ur5e ur10e ur16e; do
    echo "full loao $a stgnn_fixed 44"; echo "full loao $a anomaly_residual 44"; done
  for s in 42 43 44; do for a in ur3e ur5e ur10e ur16e; do echo "stock loao $a stgnn_fixed $s"
  done; done; } > outputs/jobs_grouped.txt
#    trained on a lent GPU (one H200, 16 cores, CUDA MPS; the 26 trainings in 223 s, 352 s with
#    the recording):
#      CAMPAIGN=outputs/campaign_arms_grouped PAR=26 BUDGET_S=480 \
#        studies/arms/gpu_networks.sh outputs/jobs_grouped.txt
#    its run directories unpacked here under outputs/campaign_arms_grouped; then, here:
$G --variants stgnn_fixed,anomaly_residual --steps rescore,commission,alarms
$G --variants stgnn_fixed --sensing stock --steps rescore,commission,alarms
$G --variants gbdt --seeds 44 --override model.severity=false --steps train,commission
mkdir -p outputs/campaign_arms_grouped/stock
ln -sfn ../../campaign_arms/stock/own outputs/campaign_arms_grouped/stock/own
$G --variants gbdt --seeds 42,43,44 --sensing stock --override model.severity=false \
  --steps train,commission
$C --out outputs/campaign_arms_grouped --stages own --variants gbdt --seeds 42 --sensing stock \
  --override model.severity=false --steps train
#    the stricter operating point (commission healthy_rate=0.99), every leave-one-arm-out model:
$G --variants gbdt,stgnn_fixed,anomaly_residual --healthy-rate 0.99 --steps commission,alarms
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_grouped \
  > studies/arms/results/table_full.md
$PY studies/arms/summarise.py --sensing stock --out outputs/campaign_arms_grouped \
  > studies/arms/results/table_stock.md
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_grouped \
  --healthy-rate 0.99 > studies/arms/results/table_full_hr0.99.md
$PY -m robohealth_mj.bench sim --duration 120 --arms ur5e,ur3e,ur10e,ur16e \
  > studies/arms/results/bench_sim.txt
# 7. gbdt's own models, seeds 43-44, on the three arms that had seed 42 alone (full sensing)
$C --variants gbdt --seeds 43,44 --override model.severity=false --stages own --steps train \
  --arms ur10e,ur16e,ur5e
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_grouped \
  > studies/arms/results/table_full.md
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_grouped \
  --healthy-rate 0.99 > studies/arms/results/table_full_hr0.99.md
# 7b. gbdt's own models in the stock profile, seeds 43-44 (they had seed 42 alone)
$C --out outputs/campaign_arms_grouped --stages own --variants gbdt --seeds 43,44 --sensing stock \
  --override model.severity=false --steps train
$PY studies/arms/summarise.py --sensing stock --out outputs/campaign_arms_grouped \
  > studies/arms/results/table_stock.md
# 8. (2026-11-27) more data per arm, the candidate named for the full profile's localisation:
#    twice the training sessions per arm (corpus.train.sessions=16: sessions 8-15 beside the
#    same eight), the leave-one-arm-out networks (stgnn_fixed and the headline, seeds 42-44) and
#    stgnn_fixed's own models (seed 42) at 30 epochs on a lent GPU, with the job list below:
#      CAMPAIGN=outputs/campaign_arms_x2 CORPUS=outputs/corpus/arms_x2 \
#        CORPUS_OVERRIDES=corpus.train.sessions=16 PAR=16 BUDGET_S=540 \
#        studies/arms/gpu_networks.sh outputs/jobs_x2.txt
#    (one H200, 16 cores, CUDA MPS; run there in two calls on one machine: 68 sessions recorded
#    and parsed in 154 s, 16 trainings in 175 s, the other 12 in 192 s), unpacked here under
#    outputs/campaign_arms_x2; here the same corpora (the first eight sessions and the held-out
#    and healthy ones linked from step 1's), gbdt seeds 42-44, and the rest:
{ for s in 42 43 44; do for a in ur3e ur5e ur10e ur16e; do
    echo "full loao $a stgnn_fixed $s"; echo "full loao $a anomaly_residual $s"; done; done
  for a in ur3e ur5e ur10e ur16e; do echo "full own $a stgnn_fixed 42"; done; } \
  > outputs/jobs_x2.txt
for arm in ur5e ur10e ur3e ur16e; do
  mkdir -p outputs/corpus/arms_x2/$arm
  for d in outputs/corpus/arms/$arm/*/; do
    ln -sfn "../../arms/$arm/$(basename "$d")" "outputs/corpus/arms_x2/$arm/$(basename "$d")"
  done
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms_x2/$arm \
    "record_overrides=[\"arm=$arm\"]" progress=false corpus.train.sessions=16
done
X="$C --out outputs/campaign_arms_x2 --corpus outputs/corpus/arms_x2"
$X --stages loao --variants gbdt --seeds 42,43,44 --override model.severity=false \
  --steps train,commission
$X --stages loao --variants stgnn_fixed,anomaly_residual --steps rescore,commission
$X --stages loao --variants stgnn_fixed --healthy-rate 0.99 --steps commission,alarms
$X --stages own --variants stgnn_fixed --steps rescore
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_x2 \
  --against outputs/campaign_arms_grouped > studies/arms/results/table_full_x2.md
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_x2 \
  --healthy-rate 0.99 > studies/arms/results/table_full_x2_hr0.99.md
# which faulted windows the graph and the trees both mislocalise, at each corpus size
{ $PY studies/arms/localisation_errors.py; echo
  $PY studies/arms/localisation_errors.py --out outputs/campaign_arms_x2 \
    --corpus outputs/corpus/arms_x2; } > studies/arms/results/localisation_errors.md
# 7. (2026-11-27) The UR20 (assets/ur20/): its corpus and the UR5e's again (the own-model recipe
#    of table_full_e10.md: seed 42, networks 10 epochs), each arm's own models side by side, the
#    UR20 left out of a model trained on the four other arms (before and after commissioning,
#    false alarms over its healthy hour), and its recorder speed (bench_sim_ur20.txt)
for arm in ur20 ur5e ur3e ur10e ur16e; do
  [ -f outputs/corpus/arms/$arm/corpus.json ] || $PY -m robohealth_mj.corpus corpus=arms \
    out_dir=outputs/corpus/arms/$arm "record_overrides=[\"arm=$arm\"]" progress=false
done
U="$C --out outputs/campaign_arms_ur20 --seeds 42"
$U --arms ur5e,ur20 --stages own --variants gbdt --override model.severity=false --steps train
$U --arms ur5e,ur20 --stages own --variants stgnn_fixed --epochs 10 --steps train
$U --arms ur20 --stages loao --variants gbdt --override model.severity=false \
  --steps train,commission
$U --arms ur20 --stages loao --variants stgnn_fixed --epochs 10 \
  --steps train,rescore,commission,alarms
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_ur20 \
  > studies/arms/results/table_ur20.md
$PY -m robohealth_mj.bench sim --duration 60 --arms ur5e,ur20,ur5e,ur20
# 8. (2026-11-27) The UR30 (assets/ur30/): its corpus, its own models and the four-arm models
#    (the UR20's recipe) beside the UR5e's and UR20's rows of step 7 (table_ur30.md), and its
#    recorder speed (bench_sim_ur30.txt)
[ -f outputs/corpus/arms/ur30/corpus.json ] || $PY -m robohealth_mj.corpus corpus=arms \
  out_dir=outputs/corpus/arms/ur30 "record_overrides=[\"arm=ur30\"]" progress=false
$U --arms ur30 --stages own --variants gbdt --override model.severity=false --steps train
$U --arms ur30 --stages own --variants stgnn_fixed --epochs 10 --steps train
$U --arms ur30 --stages loao --variants gbdt --override model.severity=false \
  --steps train,commission
$U --arms ur30 --stages loao --variants stgnn_fixed --epochs 10 \
  --steps train,rescore,commission,alarms
for arm in ur20 ur30; do  # seeds 43 and 44 of both arms' own and four-arm models
  $C --out outputs/campaign_arms_ur20 --seeds 43,44 --arms $arm --stages own --variants gbdt \
    --override model.severity=false --steps train
  $C --out outputs/campaign_arms_ur20 --seeds 43,44 --arms $arm --stages own \
    --variants stgnn_fixed --epochs 10 --steps train
  $C --out outputs/campaign_arms_ur20 --seeds 43,44 --arms $arm --stages loao --variants gbdt \
    --override model.severity=false --steps train,commission
  $C --out outputs/campaign_arms_ur20 --seeds 43,44 --arms $arm --stages loao \
    --variants stgnn_fixed --epochs 10 --steps train,rescore,commission,alarms
done
$PY studies/arms/summarise.py --sensing full --out outputs/campaign_arms_ur20 \
  > studies/arms/results/table_ur30.md
$PY -m robohealth_mj.bench sim --duration 600 --arms ur5e,ur30,ur5e,ur30,ur5e,ur30
