"""Campaign figures (thesis §3): localisation by variant, the pose × residual decomposition,
confusion matrices of the best, worst and headline models, payload shift, window ablation, |γ|,
the harness under each placement and profile, and the learned coupling beside C0."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.reporting.runs import REFERENCE
from robohealth_mj.reporting.tables.q1 import DECOMPOSITION
from robohealth_mj.schema import FAULT_CLASSES

HEADLINE = "anomaly_residual"


def figures(runs: list[dict[str, Any]], rows: list[dict[str, Any]], out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written: list[Path] = []

    def save(fig, name):
        path = out / name
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)

    ref = [r for r in rows if r["setting"] == REFERENCE]
    _localisation_bars(plt, save, ref)
    _decomposition(plt, save, ref)
    _confusions(plt, save, [r for r in runs if r["setting"] == REFERENCE])
    _payload_shift(plt, save, ref)
    _window_ablation(plt, save, ref)
    _gamma(plt, save, [r for r in rows if r["gamma"][2]])
    _harness(plt, save, [r for r in rows if r["graph"] != "structural"])
    _couplings(plt, save, [r for r in runs if r.get("coupling") is not None])
    return written


def _label(r: dict[str, Any]) -> str:
    return f"{r['variant']}\nW={r['window']}"


def _localisation_bars(plt, save, ref: list[dict]) -> None:
    sub = [r for r in ref if r["heldout.localisation_accuracy"][2]]
    if not sub:
        return
    fig, ax = plt.subplots(figsize=(max(6, 0.7 * len(sub)), 3.4))
    ax.bar(
        [_label(r) for r in sub],
        [r["heldout.localisation_accuracy"][0] for r in sub],
        yerr=[r["heldout.localisation_accuracy"][1] for r in sub],
        color=["C1" if r["variant"] == "gbdt" else "C0" for r in sub],
        capsize=3,
    )
    ax.axhline(1 / 6, color="0.5", ls="--", lw=1, label="chance (1/6)")
    ax.set_ylim(0, 1)
    ax.set_title("Localisation accuracy by variant (held-out; gbdt in orange)")
    ax.legend(fontsize=8)
    ax.tick_params(axis="x", labelsize=7, labelrotation=35)
    save(fig, "localisation_by_variant.png")


def _decomposition(plt, save, ref: list[dict]) -> None:
    """Held-out accuracy and localisation of the four (pose kernel, learned residual) variants,
    at the smallest window where all four ran."""
    windows = sorted({r["window"] for r in ref})
    for w in windows:
        cells = {
            key: next((r for r in ref if r["variant"] == v and r["window"] == w), None)
            for key, v in DECOMPOSITION.items()
        }
        if all(cells.values()):
            break
    else:
        return
    fig, axes = plt.subplots(1, 2, figsize=(8, 3.4))
    for ax, metric, title in (
        (axes[0], "heldout.accuracy", "accuracy"),
        (axes[1], "heldout.localisation_accuracy", "localisation"),
    ):
        grid = np.array(
            [[cells[(p, res)][metric][0] for res in (False, True)] for p in (False, True)]
        )
        ax.imshow(grid, vmin=grid.min() - 0.05, vmax=grid.max() + 0.02, cmap="Blues")
        for i in range(2):
            for j in range(2):
                stat = cells[(bool(i), bool(j))][metric]
                ax.text(
                    j, i, f"{stat[0]:.3f}\n± {stat[1]:.3f}", ha="center", va="center", fontsize=9
                )
        ax.set_xticks([0, 1], ["fixed A", "+ learned residual"])
        ax.set_yticks([0, 1], ["no pose kernel", "pose kernel"])
        ax.set_title(f"held-out {title}, W = {w}", fontsize=9)
    fig.suptitle("Pose × residual decomposition (thesis variants c, d, e, f)", fontsize=10)
    save(fig, "pose_residual_decomposition.png")


def _confusions(plt, save, ref_runs: list[dict]) -> None:
    """Row-normalised confusion matrices, summed over seeds, of the best and worst models by
    held-out accuracy and of the headline model."""
    groups: dict[tuple, list] = defaultdict(list)
    for r in ref_runs:
        groups[(r["label"], r["window"])].append(r)
    if not groups:
        return
    acc = {k: np.mean([m["heldout"]["accuracy"] for m in v]) for k, v in groups.items()}
    best, worst = max(acc, key=acc.get), min(acc, key=acc.get)
    headline = max((k for k in groups if k[0] == HEADLINE), key=lambda k: k[1], default=None)
    picks = [("best", best), ("worst", worst)] + ([("headline", headline)] if headline else [])
    fig, axes = plt.subplots(1, len(picks), figsize=(4.2 * len(picks), 4))
    for ax, (role, key) in zip(np.atleast_1d(axes), picks, strict=True):
        cm = sum(np.array(m["heldout"]["confusion_matrix"], float) for m in groups[key])
        cm = cm / np.maximum(cm.sum(axis=1, keepdims=True), 1)
        ax.imshow(cm, vmin=0, vmax=1, cmap="Blues")
        for i in range(len(FAULT_CLASSES)):
            ax.text(i, i, f"{cm[i, i]:.2f}", ha="center", va="center", fontsize=6)
        ax.set_xticks(range(7), FAULT_CLASSES, rotation=45, fontsize=7)
        ax.set_yticks(range(7), FAULT_CLASSES, fontsize=7)
        ax.set_xlabel("predicted", fontsize=8)
        ax.set_title(f"{role}: {key[0]} W={key[1]} (acc {acc[key]:.3f})", fontsize=9)
    save(fig, "confusion_best_worst_headline.png")


def _payload_shift(plt, save, ref: list[dict]) -> None:
    shift = [r for r in ref if r["probe.accuracy"][2]]
    if not shift:
        return
    fig, ax = plt.subplots(figsize=(max(6, 0.7 * len(shift)), 3.2))
    x = np.arange(len(shift))
    ax.bar(x - 0.2, [r["heldout.accuracy"][0] for r in shift], 0.4, label="held-out")
    ax.bar(x + 0.2, [r["probe.accuracy"][0] for r in shift], 0.4, label="payload 2.2 probe")
    ax.set_xticks(x, [_label(r) for r in shift], fontsize=7, rotation=35)
    ax.set_ylim(0, 1)
    ax.set_title("Classification accuracy: payload shift")
    ax.legend(fontsize=8)
    save(fig, "payload_shift.png")


def _window_ablation(plt, save, ref: list[dict]) -> None:
    by_model = defaultdict(list)
    for r in ref:
        by_model[r["variant"]].append(r)
    ablation = {
        v: sorted(rs, key=lambda r: r["window"]) for v, rs in by_model.items() if len(rs) > 1
    }
    if not ablation:
        return
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2))
    for ax, metric, name in (
        (axes[0], "heldout.accuracy", "accuracy"),
        (axes[1], "heldout.localisation_accuracy", "localisation"),
    ):
        for variant, rs in ablation.items():
            ax.errorbar(
                [r["window"] for r in rs],
                [r[metric][0] for r in rs],
                yerr=[r[metric][1] for r in rs],
                marker="o",
                label=variant,
            )
        ax.set_xlabel("window W (snapshots at 20 Hz)")
        ax.set_ylabel(f"held-out {name}")
    axes[0].legend(fontsize=7)
    fig.suptitle("Window ablation", fontsize=10)
    save(fig, "window_ablation.png")


def _gamma(plt, save, gammas: list[dict]) -> None:
    if not gammas:
        return
    fig, ax = plt.subplots(figsize=(6, 3))
    ax.bar(
        [f"{_label(r)}\n{r['setting']}" for r in gammas],
        [r["gamma"][0] for r in gammas],
        yerr=[r["gamma"][1] for r in gammas],
        color="C2",
        capsize=3,
    )
    ax.set_title("Converged |γ| (pose bandwidth)")
    ax.tick_params(axis="x", labelsize=6)
    save(fig, "gamma.png")


def _harness(plt, save, harness: list[dict]) -> None:
    """Localisation under each placement (x) for each model and sensing profile (bars)."""
    if not harness:
        return
    placements = list(dict.fromkeys(r["placement"] for r in harness))
    series = list(dict.fromkeys((r["variant"], r["sensing"], r["window"]) for r in harness))
    fig, ax = plt.subplots(figsize=(max(7, 1.3 * len(placements) + 0.3 * len(series)), 3.6))
    width = 0.8 / len(series)
    for k, (variant, sensing, window) in enumerate(series):
        vals, errs = [], []
        for p in placements:
            r = next(
                (
                    r
                    for r in harness
                    if (r["variant"], r["sensing"], r["window"], r["placement"])
                    == (variant, sensing, window, p)
                ),
                None,
            )
            stat = r["heldout.localisation_accuracy"] if r else (np.nan, 0.0, 0)
            vals.append(stat[0])
            errs.append(stat[1])
        ax.bar(
            np.arange(len(placements)) + (k - (len(series) - 1) / 2) * width,
            vals,
            width,
            yerr=errs,
            capsize=2,
            label=f"{variant} ({sensing}, W={window})",
        )
    ax.axhline(1 / 6, color="0.5", ls="--", lw=1)
    ax.set_xticks(range(len(placements)), placements, fontsize=8)
    ax.set_ylim(0, 1)
    ax.set_ylabel("held-out localisation")
    ax.set_title("Unknown placement: localisation by placement, model and sensing profile")
    # below the axes: with up to 12 series a legend inside would hide the bars' tops
    ax.legend(fontsize=6, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.12))
    save(fig, "harness_localisation.png")


def _couplings(plt, save, coupled: list[dict]) -> None:
    """For each (placement, profile, model): the learned softplus(C) of its best-correlated
    seed beside the true C0."""
    from robohealth_mj.data.graphs import DEFAULT_C0

    best: dict[tuple, dict] = {}
    for r in coupled:
        key = (r["placement"], r["sensing"], r["label"])
        if key not in best or r.get("coupling_correlation", -1) > best[key].get(
            "coupling_correlation", -1
        ):
            best[key] = r
    if not best:
        return
    keys = sorted(best)
    fig, axes = plt.subplots(len(keys), 2, figsize=(6, 2.4 * len(keys)), squeeze=False)
    for row, key in zip(axes, keys, strict=True):
        r = best[key]
        truth = np.array(r["coupling_truth"]) if r.get("coupling_truth") else DEFAULT_C0
        for ax, mat, title in (
            (row[0], np.array(r["coupling"]), "learned softplus(C)"),
            (row[1], truth, "true C0"),
        ):
            ax.imshow(mat / max(float(np.max(mat)), 1e-9), cmap="viridis", aspect="auto")
            ax.set_title(f"{title}: {key[0]}, {key[1]}", fontsize=7)
            ax.set_xlabel("sensor", fontsize=7)
            ax.set_ylabel("joint", fontsize=7)
        row[0].text(
            0.02,
            0.02,
            f"{key[2]} seed {r['seed']}\ncorr {r.get('coupling_correlation', float('nan')):+.3f}",
            transform=row[0].transAxes,
            fontsize=6,
            color="w",
        )
    save(fig, "coupling_vs_c0.png")
