"""Campaign tables: every run's summary and evaluations, grouped by (graph, variant, window),
as mean ± std over seeds, in Markdown and CSV."""

from __future__ import annotations

import csv
import io
import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

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


def grouped(runs: list[dict[str, Any]]) -> list[tuple[tuple[str, str, int], list[dict]]]:
    """Runs grouped by (graph, variant, window): structural graph first, variants in the
    thesis's order."""
    groups: dict[tuple, list] = defaultdict(list)
    for r in runs:
        groups[(r["graph"], r["variant"], r["window"])].append(r)

    def order(key: tuple[str, str, int]) -> tuple:
        graph, variant, window = key
        rank = VARIANT_ORDER.index(variant) if variant in VARIANT_ORDER else 99
        return (graph != "structural", graph, window, rank)

    return [(key, groups[key]) for key in sorted(groups, key=order)]


def aggregate(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    rows = []
    for key, members in grouped(runs):
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


def _held_out(member: dict[str, Any], *path: str) -> float | None:
    """A nested held-out metric, or None where the evaluation predates it."""
    value: Any = member.get("heldout", {})
    for key in path:
        if not isinstance(value, dict) or key not in value:
            return None
        value = value[key]
    return value


def visibility_markdown(runs: list[dict[str, Any]]) -> str:
    """What each model sees of each fault on the held-out session: recall per class, accuracy of
    faulted windows per severity, and on faulted windows whose faulted joint moved or stood
    still (friction acts only on a moving joint)."""
    faults = [c for c in FAULT_CLASSES if c != "none"]
    strata = [("by_severity", s) for s in ("0.3", "0.6", "0.9")] + [
        ("by_motion", m) for m in ("moving", "still")
    ]
    head = [*faults, *(f"sev. {s}" for _, s in strata[:3]), "moving", "still"]
    out = [
        "### Held-out recall per class, and accuracy by severity and by motion",
        "",
        "| graph | variant | W | " + " | ".join(head) + " |",
        "|---|---|---|" + "---|" * len(head),
    ]
    for key, members in grouped(runs):
        cells = [
            _fmt(_mean_std([_held_out(m, "per_class", c, "recall") for m in members]))
            for c in faults
        ]
        cells += [
            _fmt(_mean_std([_held_out(m, group, name, "accuracy") for m in members]))
            for group, name in strata
        ]
        out.append(f"| {key[0]} | {key[1]} | {key[2]} | " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])
