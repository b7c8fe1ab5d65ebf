"""Choosing commissioning's operating-point recipe on a validation program (ablation).

The stock models (W = 32, seeds 42-44) are commissioned on ten minutes of the pick-and-place
program's healthy running (seed 950) with each recipe of ``deploy/operating_point.py`` and
scored on the *validation* session of that program family (``val_unseen_program_seed932``);
the probe sessions (930-931) are not read here. Writes
``studies/stock_arm/results/operating_point_recipe.md``.

    .venv/bin/python studies/stock_arm/operating_point_recipe.py [CORPUS]
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_json, atomic_write_text
from robohealth_mj.deploy.commission import commission
from robohealth_mj.deploy.operating_point import RECIPES
from robohealth_mj.learn.evaluation import evaluate_checkpoint
from robohealth_mj.reporting.statistics import mean_pm_std

RESULTS = Path(__file__).resolve().parent / "results"  # its tables live there

CORPUS = Path(sys.argv[1] if len(sys.argv) > 1 else "outputs/corpus/standard")
RUNS = Path("outputs/thesis_physics/structural/stock/C0")
OUT = Path("outputs/operating_point")
CLASSES = ("none", "backlash", "friction", "jam", "struct_weaken")
VARIANTS = ("gbdt", "mlp", "stgnn_fixed")


def scores(ckpt: Path | str, data: str) -> dict:
    m = evaluate_checkpoint(ckpt, data, device="cpu")["metrics"]
    return {"accuracy": m["accuracy"], "localisation": m["localisation_accuracy"],
            "recall": {c: m["per_class"][c]["recall"] for c in CLASSES}}  # fmt: skip


def main() -> None:
    validation = str(CORPUS / "val_unseen_program_seed932")
    healthy = str(CORPUS / "healthy_program_seed950")
    rows = []
    for variant in VARIANTS:
        for seed in (42, 43, 44):
            ckpt = RUNS / variant / "w32" / f"seed{seed}" / "best.ckpt"
            for recipe in ("as trained", *RECIPES):
                done = OUT / recipe.replace(" ", "_") / variant / f"seed{seed}" / "scores.json"
                if not done.is_file():
                    start = time.perf_counter()
                    path = ckpt
                    if recipe != "as trained":
                        path = commission(ckpt, healthy, done.parent, export=False,
                                          operating_point=recipe)["checkpoint"]  # fmt: skip
                    seconds = time.perf_counter() - start
                    record = {"variant": variant, "seed": seed, "recipe": recipe,
                              "seconds": seconds, **scores(path, validation)}  # fmt: skip
                    atomic_write_json(done, record)
                rows.append(json.loads(done.read_text()))
    lines = [
        "# Commissioning's operating-point recipe, chosen on a validation program",
        "",
        "Made by `.venv/bin/python studies/stock_arm/operating_point_recipe.py "
        f"{CORPUS}`: the stock",
        "models (W = 32, mean ± std over seeds 42-44) commissioned on ten minutes of the",
        "pick-and-place program's healthy running (seed 950) and scored on the validation session",
        "of that program family (seed 932). The probe sessions (930-931) are not read.",
        "",
        "| variant | recipe | accuracy | localisation | "
        + " | ".join(f"recall {c}" for c in CLASSES)
        + " |",
        "|---|---|---|---|" + "---|" * len(CLASSES),
    ]
    for variant in VARIANTS:
        for recipe in ("as trained", *RECIPES):
            group = [r for r in rows if r["variant"] == variant and r["recipe"] == recipe]
            acc = [r["accuracy"] for r in group]
            loc = [r["localisation"] for r in group]
            recall = [f"{np.mean([r['recall'][c] for r in group]):.3f}" for c in CLASSES]
            lines.append(
                f"| {variant} | {recipe} | {mean_pm_std(acc)} | "
                f"{mean_pm_std(loc)} | " + " | ".join(recall) + " |"
            )
    out = RESULTS / "operating_point_recipe.md"
    atomic_write_text(out, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
