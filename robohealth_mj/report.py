"""``python -m robohealth_mj.report DIR``: a campaign directory -> tables and figures (thesis §3).

Reads every run's ``train_summary.json`` and ``eval_*.json`` below DIR, groups them by
(graph, variant, window) and reports mean ± std over seeds: held-out (Table 6 layout), payload
probe, harness localisation and C-C0 correlation, |gamma|. Writes ``DIR/report/results.md``,
``results.csv`` and figures, and prints the tables.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.atomic import atomic_write_text
from robohealth_mj.models import VARIANTS
from robohealth_mj.schema import FAULT_CLASSES

VARIANT_ORDER = VARIANTS
COLUMNS = (
    ("heldout", "accuracy"),
    ("heldout", "fault_present_accuracy"),
    ("heldout", "macro_f1"),
    ("heldout", "localisation_accuracy"),
    ("probe", "accuracy"),
    ("probe", "localisation_accuracy"),
)


def collect(root: Path) -> list[dict[str, Any]]:
    runs = []
    for summary_path in sorted(root.rglob("train_summary.json")):
        run_dir = summary_path.parent
        summary = json.loads(summary_path.read_text())
        row = {
            "dir": str(run_dir),
            "variant": summary["variant"],
            "window": summary["window"],
            "seed": summary["seed"],
            "graph": summary["graph"],
            "gamma": summary.get("gamma"),
            "best_epoch": summary["best_epoch"],
        }
        for name in ("heldout", "probe"):
            path = run_dir / f"eval_{name}.json"
            if path.is_file():
                result = json.loads(path.read_text())
                row[name] = result["metrics"]
                if "coupling_correlation" in result:
                    row["coupling_correlation"] = result["coupling_correlation"]
                    row["coupling"] = result["coupling"]
        if "heldout" in row:
            runs.append(row)
    return runs


def _mean_std(values: list[float]) -> tuple[float, float, int]:
    v = np.array([x for x in values if x is not None and np.isfinite(x)], dtype=float)
    if not len(v):
        return float("nan"), float("nan"), 0
    return float(v.mean()), float(v.std()), len(v)


def _fmt(stat: tuple[float, float, int]) -> str:
    mean, std, n = stat
    return "—" if n == 0 else f"{mean:.3f} ± {std:.3f}"


def aggregate(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    groups: dict[tuple, list] = defaultdict(list)
    for r in runs:
        groups[(r["graph"], r["variant"], r["window"])].append(r)

    def order(key):
        graph, variant, window = key
        rank = VARIANT_ORDER.index(variant) if variant in VARIANT_ORDER else 99
        return (graph != "structural", graph, window, rank)

    rows = []
    for key in sorted(groups, key=order):
        members = groups[key]
        row: dict[str, Any] = {
            "graph": key[0],
            "variant": key[1],
            "window": key[2],
            "seeds": sorted(m["seed"] for m in members),
        }
        for dataset, metric in COLUMNS:
            row[f"{dataset}.{metric}"] = _mean_std(
                [m.get(dataset, {}).get(metric) for m in members]
            )
        row["gamma"] = _mean_std([m.get("gamma") for m in members])
        row["coupling_correlation"] = _mean_std([m.get("coupling_correlation") for m in members])
        row["best_epoch"] = _mean_std([m["best_epoch"] for m in members])
        rows.append(row)
    return rows


def markdown(rows: list[dict[str, Any]]) -> str:
    out = []
    for graph in dict.fromkeys(r["graph"] for r in rows):
        sub = [r for r in rows if r["graph"] == graph]
        title = (
            "Held-out and payload probe (structural graph)"
            if graph == "structural"
            else f"Unknown-placement harness ({graph})"
        )
        out += [
            f"### {title}",
            "",
            "| variant | W | seeds | accuracy | fault-present | macro-F1 | localisation | "
            "probe acc. | probe loc. | |γ| | C–C0 corr. |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in sub:
            cells = [_fmt(r[f"{d}.{m}"]) for d, m in COLUMNS]
            out.append(
                f"| {r['variant']} | {r['window']} | {len(r['seeds'])} | "
                + " | ".join(cells)
                + f" | {_fmt(r['gamma'])} | "
                f"{_fmt(r['coupling_correlation'])} |"
            )
        out.append("")
    return "\n".join(out)


def write_csv(rows: list[dict[str, Any]]) -> str:
    buffer = io.StringIO()
    w = csv.writer(buffer)
    keys = [f"{d}.{m}" for d, m in COLUMNS] + ["gamma", "coupling_correlation", "best_epoch"]
    w.writerow(
        [
            "graph",
            "variant",
            "window",
            "seeds",
            *[f"{k}.{s}" for k in keys for s in ("mean", "std")],
        ]
    )
    for r in rows:
        w.writerow(
            [
                r["graph"],
                r["variant"],
                r["window"],
                len(r["seeds"]),
                *[f"{v:.6g}" for k in keys for v in r[k][:2]],
            ]
        )
    return buffer.getvalue()


def figures(runs: list[dict[str, Any]], rows: list[dict[str, Any]], out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []

    def save(fig, name):
        path = out / name
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)

    def bars(metric_key: str, title: str, name: str, graph: str = "structural"):
        sub = [r for r in rows if r["graph"] == graph and r[metric_key][2]]
        if not sub:
            return
        fig, ax = plt.subplots(figsize=(8, 3.2))
        labels = [f"{r['variant']}\nW={r['window']}" for r in sub]
        ax.bar(
            labels,
            [r[metric_key][0] for r in sub],
            yerr=[r[metric_key][1] for r in sub],
            color="C0",
            capsize=3,
        )
        ax.axhline(1 / 6, color="0.5", ls="--", lw=1, label="chance (1/6)")
        ax.set_ylim(0, 1)
        ax.set_title(title)
        ax.legend(fontsize=8)
        ax.tick_params(axis="x", labelsize=7)
        save(fig, name)

    bars(
        "heldout.localisation_accuracy",
        "Localisation accuracy by variant (held-out)",
        "localisation_by_variant.png",
    )
    bars(
        "heldout.localisation_accuracy",
        "Localisation under the harness",
        "harness_localisation.png",
        graph="harness",
    )
    shift = [r for r in rows if r["graph"] == "structural" and r["probe.accuracy"][2]]
    if shift:
        fig, ax = plt.subplots(figsize=(8, 3.2))
        x = np.arange(len(shift))
        ax.bar(x - 0.2, [r["heldout.accuracy"][0] for r in shift], 0.4, label="held-out")
        ax.bar(x + 0.2, [r["probe.accuracy"][0] for r in shift], 0.4, label="payload 2.2 probe")
        ax.set_xticks(x, [f"{r['variant']}\nW={r['window']}" for r in shift], fontsize=7)
        ax.set_ylim(0, 1)
        ax.set_title("Classification accuracy: payload shift")
        ax.legend(fontsize=8)
        save(fig, "payload_shift.png")
    by_window = defaultdict(list)
    for r in rows:
        if r["graph"] == "structural":
            by_window[r["variant"]].append(r)
    ablation = {
        v: sorted(rs, key=lambda r: r["window"]) for v, rs in by_window.items() if len(rs) > 1
    }
    if ablation:
        fig, ax = plt.subplots(figsize=(6, 3.2))
        for variant, rs in ablation.items():
            ax.errorbar(
                [r["window"] for r in rs],
                [r["heldout.accuracy"][0] for r in rs],
                yerr=[r["heldout.accuracy"][1] for r in rs],
                marker="o",
                label=variant,
            )
        ax.set_xlabel("window W (snapshots)")
        ax.set_ylabel("held-out accuracy")
        ax.set_title("Window ablation")
        ax.legend(fontsize=8)
        save(fig, "window_ablation.png")
    gammas = [r for r in rows if r["gamma"][2]]
    if gammas:
        fig, ax = plt.subplots(figsize=(6, 3))
        ax.bar(
            [f"{r['variant']}\nW={r['window']}" for r in gammas],
            [r["gamma"][0] for r in gammas],
            yerr=[r["gamma"][1] for r in gammas],
            color="C2",
            capsize=3,
        )
        ax.set_title("Converged |γ| (pose bandwidth)")
        ax.tick_params(axis="x", labelsize=7)
        save(fig, "gamma.png")
    best = max(
        (r for r in runs if r["graph"] == "structural"),
        key=lambda r: r["heldout"].get("accuracy", 0),
        default=None,
    )
    if best is not None:
        cm = np.array(best["heldout"]["confusion_matrix"], float)
        cm = cm / np.maximum(cm.sum(axis=1, keepdims=True), 1)
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        axes[0].imshow(cm, vmin=0, vmax=1, cmap="Blues")
        axes[0].set_xticks(range(7), FAULT_CLASSES, rotation=45, fontsize=7)
        axes[0].set_yticks(range(7), FAULT_CLASSES, fontsize=7)
        axes[0].set_title(
            f"Confusion (row-normalised): {best['variant']} seed {best['seed']}", fontsize=9
        )
        f1 = [best["heldout"]["per_class"][c]["f1"] for c in FAULT_CLASSES]
        axes[1].bar(FAULT_CLASSES, f1, color="C1")
        axes[1].set_ylim(0, 1)
        axes[1].set_title("Per-class F1", fontsize=9)
        axes[1].tick_params(axis="x", rotation=45, labelsize=7)
        save(fig, "confusion_and_f1.png")
    coupled = [r for r in runs if r.get("coupling") is not None and r["graph"] == "harness"]
    if coupled:
        from robohealth_mj.data.graphs import DEFAULT_C0

        r = max(coupled, key=lambda r: r.get("coupling_correlation", -1))
        fig, axes = plt.subplots(1, 2, figsize=(7, 3.4))
        for ax, mat, title in (
            (axes[0], np.array(r["coupling"]), "learned softplus(C)"),
            (axes[1], DEFAULT_C0, "ground truth C0"),
        ):
            ax.imshow(mat / mat.max(), cmap="viridis")
            ax.set_title(title, fontsize=9)
            ax.set_xlabel("harness sensor")
            ax.set_ylabel("joint")
        fig.suptitle(
            f"{r['variant']} seed {r['seed']}: corr {r['coupling_correlation']:.3f}", fontsize=9
        )
        save(fig, "coupling_vs_c0.png")
    return written


def build_report(root: Path) -> tuple[str, list[Path]]:
    runs = collect(root)
    if not runs:
        raise SystemExit(f"no finished runs (train_summary.json + eval_heldout.json) under {root}")
    rows = aggregate(runs)
    out = root / "report"
    out.mkdir(parents=True, exist_ok=True)
    text = markdown(rows)
    atomic_write_text(
        out / "results.md",
        f"# Results: {root}\n\n{len(runs)} runs; mean ± std over seeds.\n\n{text}",
    )
    atomic_write_text(out / "results.csv", write_csv(rows))
    return text, figures(runs, rows, out)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.report",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "root",
        nargs="?",
        default="outputs/campaign",
        help="campaign directory (default: outputs/campaign)",
    )
    args = parser.parse_args(argv)
    root = Path(args.root)
    text, figs = build_report(root)
    print(text)
    print(f"report: {root / 'report' / 'results.md'} (+ results.csv, {len(figs)} figures)")


if __name__ == "__main__":
    main()
