"""Reading a campaign: one row per finished run (its summary and evaluations), the values in
it, and the runs grouped by setting, model and window in the thesis's order."""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path
from typing import Any

from robohealth_mj.models import VARIANTS
from robohealth_mj.reporting.archive import SUMMARY, finished_runs
from robohealth_mj.schema import FAULT_CLASSES

VARIANT_ORDER = VARIANTS
FAULTS = tuple(c for c in FAULT_CLASSES if c != "none")
REFERENCE = "structural/full/C0"  # the setting of Tables 6 and 7


def model_label(summary: dict[str, Any]) -> str:
    """The variant, marked with the head options that change it: ``+energy`` (sign-pinned
    sensor scores), ``+severity`` (the severity head)."""
    label = summary["variant"]
    if summary.get("anomaly_scores") == "energy":
        label += "+energy"
    if summary.get("severity_head"):
        label += "+severity"
    return label


def collect(root: Path) -> list[dict[str, Any]]:
    """One row per finished run (a ``train_summary.json`` with an ``eval_heldout.json``)."""
    runs = []
    for run_dir in finished_runs(root):
        summary = json.loads((run_dir / SUMMARY).read_text())
        row = {
            "dir": str(run_dir),
            "variant": summary["variant"],
            "label": model_label(summary),
            "window": summary["window"],
            "seed": summary["seed"],
            "graph": summary["graph"],
            "sensing": summary.get("sensing", "full"),
            "placement": summary.get("placement", "C0"),
            "gamma": summary.get("gamma"),
            "best_epoch": summary["best_epoch"],
            "epochs": summary.get("epochs"),
            "wall_seconds": summary.get("wall_seconds"),
            "device": summary.get("device", "cpu"),
            "coupling_truth": summary.get("coupling_truth"),
        }
        row["setting"] = f"{row['graph']}/{row['sensing']}/{row['placement']}"
        for name in ("heldout", "probe"):
            path = run_dir / f"eval_{name}.json"
            if path.is_file():
                result = json.loads(path.read_text())
                row[name] = result["metrics"]
                if "coupling_correlation" in result:
                    row["coupling_correlation"] = result["coupling_correlation"]
                    row["coupling"] = result["coupling"]
        runs.append(row)
    return runs


def value_at(run: dict[str, Any], *path: str) -> Any:
    """A nested value of a run, or None where the run (or its evaluation) lacks it."""
    value: Any = run
    for key in path:
        if not isinstance(value, dict) or key not in value:
            return None
        value = value[key]
    return value


def recall_of(run: dict[str, Any], fault: str) -> float | None:
    """Held-out recall of ``fault``, None where its label set has no such class (no support)."""
    if not value_at(run, "heldout", "per_class", fault, "support"):
        return None
    return value_at(run, "heldout", "per_class", fault, "recall")


def variant_rank(label: str) -> int:
    base = label.split("+")[0]
    return VARIANT_ORDER.index(base) if base in VARIANT_ORDER else 99


Key = tuple[str, str, int]  # (setting, model label, window)


def grouped(runs: list[dict[str, Any]]) -> list[tuple[Key, list[dict]]]:
    """Runs grouped by (setting, model, window): the reference setting first, then the harness
    settings; models in the thesis's order."""
    groups: dict[Key, list] = defaultdict(list)
    for r in runs:
        groups[(r["setting"], r["label"], r["window"])].append(r)

    def order(key: Key) -> tuple:
        setting, label, window = key
        graph, sensing, placement = setting.split("/")
        return (
            graph != "structural",
            graph,
            sensing,
            placement != "C0",
            placement,
            window,
            variant_rank(label),
            label,
        )

    return [(key, groups[key]) for key in sorted(groups, key=order)]
