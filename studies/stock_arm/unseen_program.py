"""Programs unlike the curriculum: the stock models on two pick-and-place / palletising sessions
(family pick_place, seeds 930-931, nominal arm), as trained and commissioned on ten minutes of
that program's healthy running (seed 950), beside the held-out session.

    .venv/bin/python -m robohealth_mj.record seed=950 faults=none session.duration_s=600 \\
        'curriculum.families=[pick_place]' 'curriculum.speed_scales=[0.6,1.0,1.5]' \\
        'curriculum.payload_scales=[0.5,1.0,1.6]' session.progress=false \\
        session.out_dir=CORPUS/healthy_program_seed950
    .venv/bin/python studies/stock_arm/unseen_program.py [CORPUS]

writes studies/stock_arm/results/unseen_program.md.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_json, atomic_write_text
from robohealth_mj.deploy.commission import commission
from robohealth_mj.learn.evaluation import evaluate_checkpoint
from robohealth_mj.reporting.statistics import mean_pm_std

RESULTS = Path(__file__).resolve().parent / "results"  # its tables live there

CORPUS = Path(sys.argv[1] if len(sys.argv) > 1 else "outputs/corpus/standard")
RUNS = Path("outputs/thesis_physics/structural/stock/C0")
OUT = Path("outputs/unseen_program")
CLASSES = ("none", "backlash", "friction", "jam", "struct_weaken")


def summary(m: dict) -> dict:
    moving = m.get("by_motion", {}).get("moving", {}).get("accuracy")
    recall = {c: m["per_class"][c]["recall"] for c in CLASSES}
    return {"accuracy": m["accuracy"], "localisation": m["localisation_accuracy"],
            "moving": moving, "recall": recall}  # fmt: skip


def main() -> None:
    program = [str(p) for p in sorted(CORPUS.glob("probe_unseen_program_seed*"))]
    healthy = str(CORPUS / "healthy_program_seed950")
    rows = []
    for ckpt in sorted(RUNS.glob("*/w32/seed*/best.ckpt")):
        variant, seed = ckpt.parts[-4], ckpt.parts[-2]
        done = OUT / variant / seed / "scores.json"
        if not done.is_file():
            heldout = evaluate_checkpoint(ckpt, str(CORPUS / "heldout_seed900"))["metrics"]
            before = evaluate_checkpoint(ckpt, program)["metrics"]
            record = commission(ckpt, healthy, OUT / variant / seed, export=False)
            after = evaluate_checkpoint(record["checkpoint"], program)["metrics"]
            atomic_write_json(done, {"variant": variant, "seed": seed,
                                     "heldout": summary(heldout), "before": summary(before),
                                     "after": summary(after)})  # fmt: skip
        rows.append(json.loads(done.read_text()))
    lines = [
        "# An unseen program (stock profile, W = 32)",
        "",
        f"Made by `.venv/bin/python studies/stock_arm/unseen_program.py {CORPUS}`:",
        "two sessions of pick-and-place and palletising cycles (point-to-point moves with dwells;",
        "no training session ran them), nominal arm, as trained and after commissioning on ten",
        "minutes of this program's healthy running. Mean ± std over three seeds; `moving`:",
        "faulted windows whose faulted joint moved.",
        "",
        "| variant | set | accuracy | localisation | acc. moving | "
        + " | ".join(f"recall {c}" for c in CLASSES)
        + " |",
        "|---|---|---|---|---|" + "---|" * len(CLASSES),
    ]
    for variant in sorted({r["variant"] for r in rows}, key=lambda v: (v != "gbdt", v)):
        group = [r for r in rows if r["variant"] == variant]
        for key, name in (("heldout", "held-out"), ("before", "program"),
                          ("after", "program, commissioned")):  # fmt: skip
            sets = [r[key] for r in group]

            def ms(k: str, sets=sets) -> str:
                return mean_pm_std([s[k] for s in sets])

            recalls = [f"{np.mean([s['recall'][c] for s in sets]):.3f}" for c in CLASSES]
            cells = [ms("accuracy"), ms("localisation"), ms("moving"), *recalls]
            lines.append(f"| {variant} | {name} | " + " | ".join(cells) + " |")
    atomic_write_text(RESULTS / "unseen_program.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
