#!/usr/bin/env bash
# A CPU-sized slice of the campaign on the standard corpus (no GPU lent to this task), made with
# the thesis backbone and recipe of commit eed42d5 (before the window backbone); run it there.
cd "$(dirname "$0")/../.." && . .venv/bin/activate
python -c "
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.arrays import expand_paths
load_recordings(expand_paths(['outputs/corpus/standard/train_*']))
load_recordings(expand_paths(['outputs/corpus/standard/heldout_seed900']))
load_recordings(expand_paths(['outputs/corpus/standard/probe_payload_high_seed901']))
print('caches built')
"
python -m robohealth_mj.train -m variant=mlp,stgnn_fixed,anomaly_residual graph=structural,harness \
  seed=42 window=16 trainer.epochs=10 trainer.max_windows_per_epoch=15000 trainer.progress=false \
  threads=1 hydra/launcher=local hydra.sweep.dir=outputs/campaign_cpu
python -m robohealth_mj.report outputs/campaign_cpu
