#!/usr/bin/env bash
# The fleet-runtime issue's measurements, with the headline model (anomaly_residual, W = 32,
# seed 42, exported with its incremental form). Run from the repository root on an otherwise idle
# machine (the stream benchmark times 50 ms ticks); about 30 min on 2 cores after the standard
# corpus exists (studies/earlier_campaigns/run_headline_physics.sh records it).
set -euo pipefail
PY=${PY:-.venv/bin/python}
M=studies/earlier_campaigns/results/headline_physics/anomaly_residual_w32_seed42.onnx
GRID="curriculum.speed_scales=[0.6,1.0,1.5] curriculum.payload_scales=[0.5,1.0,1.6] session.passes=1"
$PY -m robohealth_mj.export ckpt=outputs/campaign_physics/structural/anomaly_residual/w32/seed42/best.ckpt out=$M
# alarm settings chosen on selection sessions of their own seeds (never on the held-out one):
# a fault session (detection, latency) and two hours of healthy running (false alarms per hour)
$PY -m robohealth_mj.record seed=902 $GRID session.progress=false hydra.run.dir=outputs/alarm_selection/seed902
$PY -m robohealth_mj.record seed=904 faults=none session.duration_s=7200 session.progress=false \
  hydra.run.dir=outputs/alarm_selection/healthy904
$PY -m robohealth_mj.tune_alarms --model $M --data outputs/alarm_selection/seed902/graphs.jsonl \
  --healthy outputs/alarm_selection/healthy904/graphs.jsonl > studies/fleet/results/alarm_selection.md
# on-line evaluation: the standard held-out replay, and two more hours of healthy running
$PY -m robohealth_mj.monitor model=$M source=replay file=outputs/corpus/standard/heldout_seed900/graphs.jsonl \
  evaluate=true quiet=true out=studies/fleet/results/online_eval_heldout900.json
$PY -m robohealth_mj.record seed=903 faults=none session.duration_s=7200 session.progress=false \
  hydra.run.dir=outputs/alarm_selection/healthy903
$PY -m robohealth_mj.monitor model=$M source=replay file=outputs/alarm_selection/healthy903/graphs.jsonl \
  evaluate=true quiet=true out=studies/fleet/results/online_eval_healthy903.json
# throughput, soak, latency
$PY -m robohealth_mj.bench streams > studies/fleet/results/bench_streams.txt
$PY -m robohealth_mj.bench soak > studies/fleet/results/bench_soak.txt
$PY -m robohealth_mj.bench infer --model $M --data outputs/corpus/standard/heldout_seed900 \
  > studies/fleet/results/bench_infer_headline.txt
# the contact watch's cost per tick, every stream holding a pose (2026-11-27, seventeenth session)
$PY -m robohealth_mj.bench contact > studies/fleet/results/bench_contact.txt
