#!/usr/bin/env bash
# Issue 36's cross-arm experiment as run on 2026-11-26, from the repository root: the networks at
# 30 epochs on a lent GPU, everything else on 2 cores here (about 2 hours).
#   1. each arm's corpus (conf/corpus/arms.yaml: eight training sessions, a held-out one, ten
#      healthy minutes to commission on, a healthy hour to count false alarms on);
#   2. on the lent GPU: experiments/arms/gpu_networks.sh (stgnn_fixed and the headline
#      anomaly_residual, own and leave-one-arm-out, seeds 42-44, full and stock sensing; the run
#      directories unpacked here under outputs/campaign_arms);
#   3. here: gbdt (leave-one-arm-out seeds 42-44, own models seed 42; its severity booster off, as
#      the experiment scores class and joint and that booster changes neither), every network
#      scored again on this machine's recording of the held-out session, each leave-one-arm-out
#      model commissioned on the unseen arm's ten healthy minutes and scored, each commissioned
#      network's alarms counted over the unseen arm's healthy hour;
#   4. the tables (results/arms/table_full.md, table_stock.md) and the recorder per arm.
# The 10-epoch campaign of 2026-11-25 (own models seed 42, networks 10 epochs, full sensing) is
# results/arms/table_full_e10.md; its relative-channel ablation results/arms/raw_channels.md.
set -euo pipefail
PY=${PY:-.venv/bin/python}
for arm in ur5e ur10e ur3e ur16e; do
  $PY -m robohealth_mj.corpus corpus=arms out_dir=outputs/corpus/arms/$arm \
    "record_overrides=[\"arm=$arm\"]" progress=false
done
# step 2 runs on the GPU machine; then, here:
#   tar -xzf campaign_arms_gpu.tgz   (outputs/campaign_arms/{full,stock}/{own,loao}/<arm>/...)
C="$PY experiments/arms/campaign.py"
$C --variants gbdt --seeds 42,43,44 --override model.severity=false --stages loao \
  --steps train,commission
$C --variants gbdt --seeds 42 --override model.severity=false --stages own --steps train
$C --variants stgnn_fixed,anomaly_residual --steps rescore,commission,alarms
$C --variants stgnn_fixed --sensing stock --steps rescore,commission
for sensing in full stock; do
  $PY experiments/arms/summarise.py --sensing $sensing > "results/arms/table_$sensing.md"
done
$PY -m robohealth_mj.bench sim --duration 120 --arms ur5e,ur3e,ur10e,ur16e \
  > results/arms/bench_sim.txt
