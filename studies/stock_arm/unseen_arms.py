"""Unseen arms, before and after commissioning: the stock models of the campaign on three
sessions each run by its own drawn arm (conf/arm/varied.yaml), commissioned on ten minutes of
that arm's healthy running (python -m robohealth_mj.commission), beside the held-out session.

    .venv/bin/python studies/stock_arm/unseen_arms.py [CORPUS] [RUNS]

writes studies/stock_arm/results/unseen_arms.md.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_json, atomic_write_text
from robohealth_mj.deploy.commission import commission
from robohealth_mj.learn.evaluation import evaluate_checkpoint
from robohealth_mj.reporting.statistics import mean_pm_std

RESULTS = Path(__file__).resolve().parent / "results"  # its tables live there

CORPUS = Path(sys.argv[1] if len(sys.argv) > 1 else "outputs/corpus/standard")
RUNS = Path(sys.argv[2] if len(sys.argv) > 2 else "outputs/thesis_physics/structural/stock/C0")
OUT = Path("outputs/unseen_arms")
ARMS = (910, 911, 912)
PROGRAM = "probe_unseen_program"
KEYS = ("accuracy", "macro_f1", "localisation_accuracy")


def variants(rows: dict) -> list[str]:
    """The variants in table order: the `gbdt` reference first, then by name."""
    return sorted({r["variant"] for r in rows.values()}, key=lambda v: (v != "gbdt", v))


def scores(metrics: dict) -> dict:
    out = {k: metrics[k] for k in KEYS}
    out["recall"] = {c: v["recall"] for c, v in metrics["per_class"].items() if v["support"]}
    return out


def nominal_scores(ckpt: Path) -> dict:
    """The same programs and fault schedules run by the nominal arm (the reference)."""
    return {
        arm: scores(
            evaluate_checkpoint(ckpt, str(CORPUS / f"probe_nominal_arms_seed{arm}"))["metrics"]
        )
        for arm in ARMS
    }


def program_scores(ckpt: Path) -> dict:
    """The pick-and-place and palletising sessions (nominal arm): programs unlike the sweeps."""
    paths = [str(p) for p in sorted(CORPUS.glob(f"{PROGRAM}_seed*"))]
    return scores(evaluate_checkpoint(ckpt, paths)["metrics"])


def main() -> None:
    rows = {}
    for ckpt in sorted(RUNS.glob("*/w32/seed*/best.ckpt")):
        variant, seed = ckpt.parts[-4], ckpt.parts[-2]
        key = f"{variant}/{seed}"
        done = OUT / variant / seed / "scores.json"
        row = json.loads(done.read_text()) if done.is_file() else {}
        if "nominal" not in row and row:  # the reference sessions, added after the first runs
            row["nominal"] = nominal_scores(ckpt)
            atomic_write_json(done, row)
        if "program" not in row and row and (CORPUS / f"{PROGRAM}_seed930").is_dir():
            row["program"] = program_scores(ckpt)
            atomic_write_json(done, row)
        if row:
            rows[key] = row
            continue
        started = time.perf_counter()
        heldout = json.loads((ckpt.parent / "eval_heldout.json").read_text())["metrics"]
        row = {"variant": variant, "seed": seed, "heldout": scores(heldout), "arms": {}}
        row["nominal"] = nominal_scores(ckpt)
        for arm in ARMS:
            probe = str(CORPUS / f"probe_unseen_arms_seed{arm}")
            healthy = str(CORPUS / f"healthy_unseen_arms_seed{arm}")
            before = evaluate_checkpoint(ckpt, probe)["metrics"]
            record = commission(ckpt, healthy, OUT / variant / seed / f"arm{arm}", export=False)
            after = evaluate_checkpoint(record["checkpoint"], probe)["metrics"]
            row["arms"][arm] = {
                "before": scores(before),
                "after": scores(after),
                "settled_minutes": record["settled_minutes"],
            }
            print(f"{key} arm {arm}: acc {before['accuracy']:.3f} -> {after['accuracy']:.3f}  "
                  f"loc {before['localisation_accuracy']:.3f} -> "
                  f"{after['localisation_accuracy']:.3f}", flush=True)  # fmt: skip
        row["seconds"] = time.perf_counter() - started
        atomic_write_json(done, row)
        rows[key] = row
    atomic_write_text(RESULTS / "unseen_arms.md", table(rows))


def program_lines(rows: dict) -> list[str]:
    """Programs unlike the curriculum, beside the held-out session and the nominal-arm probes."""
    if not any("program" in r for r in rows.values()):
        return []
    lines = [
        "",
        "Unseen programs: two sessions of pick-and-place and palletising cycles (family",
        "`pick_place`, seeds 930-931, nominal arm), which no training session ran:",
        "",
        "| variant | seeds | held-out acc. / loc. | nominal-arm probes | unseen program |",
        "|---|---|---|---|---|",
    ]
    for variant in variants(rows):
        group = [r for r in rows.values() if r["variant"] == variant and "program" in r]
        if not group:
            continue
        nominal = [n for r in group for n in r["nominal"].values()]

        def pair(sets: list[dict]) -> str:
            acc = np.mean([m["accuracy"] for m in sets])
            loc = np.mean([m["localisation_accuracy"] for m in sets])
            return f"{acc:.3f} / {loc:.3f}"

        cells = [pair([r["heldout"] for r in group]), pair(nominal),
                 pair([r["program"] for r in group])]  # fmt: skip
        lines.append(f"| {variant} | {len(group)} | " + " | ".join(cells) + " |")
    return lines


def alarm_lines() -> list[str]:
    """The on-line alarms of studies/stock_arm/run_alarms.sh, where it has run."""
    runs = {p.stem: json.loads(p.read_text()) for p in (OUT / "monitor").glob("*.json")}
    if not runs:
        return []
    lines = [
        "",
        "On-line, `stgnn_fixed` seed 42 exported to ONNX, the monitor's default alarm policy",
        f"(`bash studies/stock_arm/run_alarms.sh {CORPUS}`), summed over the three sessions:",
        "",
        "| arm | episodes detected | right class and joint at the rise | false alarms | "
        "healthy hours | false alarms / h | on-line accuracy |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in ("nominal", "unseen", "commissioned", "healthy_before", "healthy_after"):
        group = [r for k, r in runs.items() if k.rsplit("_", 1)[0] == name]
        if not group:
            continue
        detected = sum(r["alarms"]["detected"] for r in group)
        episodes = sum(r["alarms"]["episodes"] for r in group)
        right = sum(r["alarms"]["right_at_rise"] for r in group)
        false = sum(r["false_alarms"] for r in group)
        hours = sum(r["settled_healthy_ticks"] for r in group) / 20.0 / 3600.0
        acc = np.mean([r["online_accuracy"] for r in group])
        label = {"nominal": "nominal", "unseen": "unseen, before",
                 "commissioned": "unseen, commissioned",
                 "healthy_before": "unseen, 20 healthy min each, before",
                 "healthy_after": "unseen, 20 healthy min each, commissioned"}[name]  # fmt: skip
        lines.append(f"| {label} | {detected} / {episodes} | {right} | {false} | {hours:.2f} | "
                     f"{false / hours:.2f} | {acc:.3f} |")  # fmt: skip
    return lines


_ms = mean_pm_std


def table(rows: dict) -> str:
    lines = [
        "# Unseen arms, before and after commissioning (stock profile, W = 32)",
        "",
        f"Made by `.venv/bin/python studies/stock_arm/unseen_arms.py {CORPUS}` on the",
        "2-core machine. Three probe sessions (seeds 910-912), each run by its own arm drawn from",
        "its seed (drive friction and damping ±30 %, link masses ±15 %, drive stiffness and rotor",
        "inertia ±10 %; the controller keeps the nominal model); each model commissioned per arm",
        "on ten minutes of that arm's healthy running. The reference: the same three sessions",
        "(programs, fault schedules, noise) run by the nominal arm. Mean ± std over seeds, arms.",
        "",
        "| variant | seeds | held-out acc. / loc. | nominal arm acc. | unseen arms acc. before |"
        " after | nominal arm loc. | unseen loc. before | after | baseline settled (min) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for variant in variants(rows):
        group = [r for r in rows.values() if r["variant"] == variant]
        arms = [a for r in group for a in r["arms"].values()]
        settled = [a["settled_minutes"] for a in arms if a["settled_minutes"] is not None]
        nominal = [n for r in group for n in r["nominal"].values()]
        cells = [
            f"{np.mean([r['heldout']['accuracy'] for r in group]):.3f} / "
            f"{np.mean([r['heldout']['localisation_accuracy'] for r in group]):.3f}",
            _ms([n["accuracy"] for n in nominal]),
            _ms([a["before"]["accuracy"] for a in arms]),
            _ms([a["after"]["accuracy"] for a in arms]),
            _ms([n["localisation_accuracy"] for n in nominal]),
            _ms([a["before"]["localisation_accuracy"] for a in arms]),
            _ms([a["after"]["localisation_accuracy"] for a in arms]),
            f"{max(settled):g}" if len(settled) == len(arms) else "not within 10 min",
        ]
        lines.append(f"| {variant} | {len(group)} | " + " | ".join(cells) + " |")
    lines += program_lines(rows)
    lines += alarm_lines()
    lines += ["", "Per class (recall, mean over seeds and arms):", ""]
    classes = ["none", "backlash", "friction", "jam", "struct_weaken"]
    lines += [
        "| variant | set | " + " | ".join(classes) + " |",
        "|---|---|" + "---|" * len(classes),
    ]
    for variant in variants(rows):
        group = [r for r in rows.values() if r["variant"] == variant]
        arms = [a for r in group for a in r["arms"].values()]
        nominal = [n for r in group for n in r["nominal"].values()]
        for name, sets in (("held-out", [r["heldout"] for r in group]),
                           ("nominal arms", nominal),
                           ("unseen, before", [a["before"] for a in arms]),
                           ("unseen, after", [a["after"] for a in arms])):  # fmt: skip
            cells = [f"{np.mean([s['recall'][c] for s in sets]):.3f}" for c in classes]
            lines.append(f"| {variant} | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
