"""Draws ablation.png from ablation.csv (the models issue's ablation table).

python studies/ablation_models/figure.py
"""

import csv
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

RESULTS = Path(__file__).resolve().parent / "results"  # its tables live there
rows = list(csv.DictReader((RESULTS / "ablation.csv").open()))
labels = [r["change"] for r in rows]
acc = [float(r["accuracy"]) for r in rows]
loc = [float(r["localisation"]) for r in rows]
secs = [float(r["train_s"]) for r in rows]
fig, (a, b) = plt.subplots(1, 2, figsize=(12, 0.45 * len(rows) + 1.5), sharey=True)
y = range(len(rows))
a.barh([i + 0.2 for i in y], acc, 0.4, label="accuracy")
a.barh([i - 0.2 for i in y], loc, 0.4, label="localisation")
a.set_xlim(0.70, 0.95)
a.set_yticks(list(y), labels)
a.invert_yaxis()
a.set_xlabel("held-out (standard corpus, seed 900), W = 32, seed 42")
a.legend(loc="lower left")
b.barh(list(y), secs, color="grey")
b.set_xlabel("training seconds (one thread; 2-4 runs shared the 2 cores)")
fig.tight_layout()
fig.savefig(RESULTS / "ablation.png", dpi=120)
