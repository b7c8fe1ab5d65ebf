"""Campaign figures (thesis §3): localisation by variant, confusion and F1, payload shift, harness
localisation and the learned coupling against C0."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.schema import FAULT_CLASSES


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
