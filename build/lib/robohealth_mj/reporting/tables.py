"""Campaign tables: every run's summary and evaluations, grouped by setting (graph, sensing
profile, placement), model (variant plus head options) and window, as mean ± std over seeds, in
the thesis's layout (Tables 6, 7 and 8) and in CSV."""

from __future__ import annotations

import csv
import io
import json
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.models import VARIANTS
from robohealth_mj.reporting.archive import SUMMARY, finished_runs
from robohealth_mj.schema import FAULT_CLASSES

VARIANT_ORDER = VARIANTS
FAULTS = tuple(c for c in FAULT_CLASSES if c != "none")
COLUMNS = (
    ("heldout", "accuracy"),
    ("heldout", "fault_present_accuracy"),
    ("heldout", "macro_f1"),
    ("heldout", "localisation_accuracy"),
    ("probe", "accuracy"),
    ("probe", "localisation_accuracy"),
)
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


def _mean_std(values: list[float | None]) -> tuple[float, float, int]:
    v = np.array([x for x in values if x is not None and np.isfinite(x)], dtype=float)
    if not len(v):
        return float("nan"), float("nan"), 0
    return float(v.mean()), float(v.std()), len(v)


def _fmt(stat: tuple[float, float, int], digits: int = 3) -> str:
    mean, std, n = stat
    return "—" if n == 0 else f"{mean:.{digits}f} ± {std:.{digits}f}"


def _get(run: dict[str, Any], *path: str) -> Any:
    """A nested value of a run, or None where the run (or its evaluation) lacks it."""
    value: Any = run
    for key in path:
        if not isinstance(value, dict) or key not in value:
            return None
        value = value[key]
    return value


def _recall(run: dict[str, Any], fault: str) -> float | None:
    """Held-out recall of ``fault``, None where its label set has no such class (no support)."""
    if not _get(run, "heldout", "per_class", fault, "support"):
        return None
    return _get(run, "heldout", "per_class", fault, "recall")


def _rank(label: str) -> int:
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
            _rank(label),
            label,
        )

    return [(key, groups[key]) for key in sorted(groups, key=order)]


def aggregate(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    rows = []
    for (setting, label, window), members in grouped(runs):
        row: dict[str, Any] = {
            "setting": setting,
            "graph": members[0]["graph"],
            "sensing": members[0]["sensing"],
            "placement": members[0]["placement"],
            "variant": label,
            "window": window,
            "seeds": sorted(m["seed"] for m in members),
        }
        for dataset, metric in COLUMNS:
            row[f"{dataset}.{metric}"] = _mean_std([_get(m, dataset, metric) for m in members])
        row["gamma"] = _mean_std([m.get("gamma") for m in members])
        row["coupling_correlation"] = _mean_std([m.get("coupling_correlation") for m in members])
        row["best_epoch"] = _mean_std([m["best_epoch"] for m in members])
        row["wall_seconds"] = _mean_std([m.get("wall_seconds") for m in members])
        for fault in FAULTS:
            row[f"loc.{fault}"] = _mean_std(
                [_get(m, "heldout", "per_class", fault, "localisation") for m in members]
            )
        rows.append(row)
    return rows


def _table(title: str, head: list[str]) -> list[str]:
    """A Markdown table's title and header lines."""
    return [f"### {title}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]


_MAIN_HEAD = (
    "| variant | W | seeds | accuracy | fault-present | macro-F1 | localisation | "
    "probe acc. | probe loc. | |γ| | s / run |"
)


def _main_row(r: dict[str, Any]) -> str:
    cells = [_fmt(r[f"{d}.{m}"]) for d, m in COLUMNS]
    wall = r["wall_seconds"]
    return (
        f"| {r['variant']} | {r['window']} | {len(r['seeds'])} | "
        + " | ".join(cells)
        + f" | {_fmt(r['gamma'])} | {'—' if not wall[2] else f'{wall[0]:.0f}'} |"
    )


def table6(rows: list[dict[str, Any]]) -> str:
    """Table 6's layout, once per window of the reference setting (structural graph, every
    channel, the schema's sensors)."""
    out = []
    ref = [r for r in rows if r["setting"] == REFERENCE]
    for window in sorted({r["window"] for r in ref}):
        sub = [r for r in ref if r["window"] == window]
        if len(sub) < 2:
            continue  # one model at this window: a window-ablation point, in Table 7
        out += [f"### Table 6: every model at W = {window} (held-out session; payload probe)", ""]
        out += [_MAIN_HEAD, "|---|---|---|---|---|---|---|---|---|---|---|"]
        out += [_main_row(r) for r in sub]
        out.append("")
    return "\n".join(out)


def table7(rows: list[dict[str, Any]]) -> str:
    """Table 7's layout: held-out accuracy / localisation per window, for each model run at
    more than one window in the reference setting."""
    ref = [r for r in rows if r["setting"] == REFERENCE]
    by_model: dict[str, dict[int, dict]] = defaultdict(dict)
    for r in ref:
        by_model[r["variant"]][r["window"]] = r
    models = {m: ws for m, ws in by_model.items() if len(ws) > 1}
    if not models:
        return ""
    windows = sorted({w for ws in models.values() for w in ws})
    out = [
        "### Table 7: window ablation (held-out accuracy / localisation, mean ± std over seeds)",
        "",
        "| variant | " + " | ".join(f"W = {w}" for w in windows) + " |",
        "|---|" + "---|" * len(windows),
    ]
    for model in sorted(models, key=_rank):
        cells = []
        for w in windows:
            r = models[model].get(w)
            cells.append(
                "—"
                if r is None
                else " / ".join(
                    _fmt(r[k], 2) for k in ("heldout.accuracy", "heldout.localisation_accuracy")
                )
            )
        out.append(f"| {model} | " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])


def table8(rows: list[dict[str, Any]]) -> str:
    """Table 8's layout: the harness under each sensing profile and placement, with the
    coupling's correlation to the truth and localisation per fault class."""
    sub = [r for r in rows if r["graph"] != "structural"]
    if not sub:
        return ""
    head = [
        "profile",
        "placement",
        "variant",
        "W",
        "seeds",
        "accuracy",
        "macro-F1",
        "localisation",
        "corr(C, C0)",
        *(f"loc. {f}" for f in FAULTS),
    ]
    out = _table("Table 8: unknown placement (harness graph) by sensing profile, placement", head)
    for r in sub:
        cells = [
            r["sensing"],
            r["placement"],
            r["variant"],
            str(r["window"]),
            str(len(r["seeds"])),
            _fmt(r["heldout.accuracy"]),
            _fmt(r["heldout.macro_f1"]),
            _fmt(r["heldout.localisation_accuracy"]),
            _fmt(r["coupling_correlation"]),
            *(_fmt(r[f"loc.{f}"], 2) for f in FAULTS),
        ]
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])


def _paired_cells(
    effect: Callable[[int, str], float], seeds: list[int], metrics: tuple[str, ...]
) -> list[str]:
    """One ``mean ± std`` cell per metric of a per-seed difference ``effect(seed, metric)``:
    the paired comparison both research questions' tables make."""
    cells = []
    for metric in metrics:
        mean, std, _ = _mean_std([effect(seed, metric) for seed in seeds])
        cells.append(f"{mean:+.3f} ± {std:.3f}")
    return cells


# The thesis's 2 x 2 (Q1): (pose kernel, learned residual) -> variant
DECOMPOSITION = {
    (False, False): "stgnn_fixed",
    (True, False): "stgnn_fixed_pose",
    (False, True): "stgnn_learnable",
    (True, True): "stgnn_pose_cond",
}


def decomposition_markdown(runs: list[dict[str, Any]]) -> str:
    """Q1 as paired effects: per seed, the pose kernel's effect (with the pose kernel minus
    without, averaged over the residual's two levels) and the learned residual's, on held-out
    accuracy and localisation, mean ± std over the seeds every cell of the 2 x 2 has. Paired,
    because the four variants of one seed see the same data in the same order: the seed's own
    luck cancels, which a comparison of means over seeds leaves in."""
    ref = [r for r in runs if r["setting"] == REFERENCE and r["label"] in DECOMPOSITION.values()]
    out = []
    for window in sorted({r["window"] for r in ref}):
        cell = {(r["label"], r["seed"]): r for r in ref if r["window"] == window}
        seeds = sorted(
            seed
            for seed in {s for _, s in cell}
            if all((v, seed) in cell for v in DECOMPOSITION.values())
        )
        if not seeds:
            continue
        if not out:
            out = _table(
                "Q1: the pose kernel and the learned residual, paired over seeds (held-out)",
                ["W", "seeds", "effect", "accuracy", "localisation", "macro-F1"],
            )
        for factor, name in ((0, "pose kernel"), (1, "learned residual")):
            on = [v for k, v in DECOMPOSITION.items() if k[factor]]
            off = [v for k, v in DECOMPOSITION.items() if not k[factor]]

            def effect(seed: int, metric: str, cell=cell, on=on, off=off) -> float:
                return float(
                    np.mean([_get(cell[v, seed], "heldout", metric) for v in on])
                    - np.mean([_get(cell[v, seed], "heldout", metric) for v in off])
                )

            cells = [str(window), str(len(seeds)), name]
            cells += _paired_cells(effect, seeds, ("accuracy", "localisation_accuracy", "macro_f1"))
            out.append("| " + " | ".join(cells) + " |")
    return "\n".join([*out, ""]) if out else ""


# Q2's model: the learned joint-sensor coupling with sign-pinned sensor scores
COUPLING_HEAD = "anomaly_residual+energy"


def coupling_markdown(runs: list[dict[str, Any]]) -> str:
    """Q2 as paired differences: under each harness setting (sensing profile, placement) and
    window, the coupling head minus every other model run there, per seed, on held-out
    localisation, accuracy and macro-F1; mean ± std over the seeds both have. Paired for Q1's
    reason: a seed's luck is shared by the models of that seed."""
    harness = [r for r in runs if r["graph"] == "harness"]
    out: list[str] = []
    for setting, window in dict.fromkeys((r["setting"], r["window"]) for r in harness):
        cell = {
            (r["label"], r["seed"]): r
            for r in harness
            if (r["setting"], r["window"]) == (setting, window)
        }
        head_seeds = {seed for label, seed in cell if label == COUPLING_HEAD}
        others = sorted(
            {label for label, _ in cell if label != COUPLING_HEAD},
            key=lambda label: (_rank(label), label),
        )
        for other in others:
            seeds = sorted(head_seeds & {seed for label, seed in cell if label == other})
            if not seeds:
                continue
            if not out:
                out = _table(
                    f"Q2: the coupling head ({COUPLING_HEAD}) minus each model under the "
                    "harness, paired over seeds (held-out)",
                    ["setting", "W", "seeds", "minus", "localisation", "accuracy", "macro-F1"],
                )

            def difference(seed: int, metric: str, cell=cell, other=other) -> float:
                return _get(cell[COUPLING_HEAD, seed], "heldout", metric) - _get(
                    cell[other, seed], "heldout", metric
                )

            cells = [setting, str(window), str(len(seeds)), other]
            cells += _paired_cells(
                difference, seeds, ("localisation_accuracy", "accuracy", "macro_f1")
            )
            out.append("| " + " | ".join(cells) + " |")
    return "\n".join([*out, ""]) if out else ""


def severity_markdown(runs: list[dict[str, Any]]) -> str:
    """The severity head (thesis §4.7): MAE on faulted windows overall, per class and per true
    severity, beside what the same model without the head reaches (its cost)."""
    with_head = [r for r in runs if r["label"].endswith("+severity")]
    if not with_head:
        return ""
    levels = sorted({k for r in with_head for k in (_get(r, "heldout", "by_severity") or {})})
    head = [
        "setting",
        "variant",
        "W",
        "seeds",
        "MAE (faulted)",
        *(f"MAE {f}" for f in FAULTS),
        *(f"MAE sev. {s}" for s in levels),
        "accuracy",
        "localisation",
    ]
    out = _table("Severity head: mean absolute error on faulted windows (held-out)", head)
    keys = dict.fromkeys((r["setting"], r["label"], r["window"]) for r in with_head)
    for setting, label, window in keys:
        members = [
            r
            for r in with_head
            if (r["setting"], r["label"], r["window"]) == (setting, label, window)
        ]
        base = label.removesuffix("+severity")
        twins = [
            r for r in runs if (r["setting"], r["label"], r["window"]) == (setting, base, window)
        ]
        for name, group in ((label, members), (f"{base} (no head)", twins)):
            if not group:
                continue
            has_head = group is members

            def stat(*path, digits=3, needs_head=True, group=group, has_head=has_head) -> str:
                if needs_head and not has_head:
                    return "—"
                return _fmt(_mean_std([_get(m, "heldout", *path) for m in group]), digits)

            cells = [
                setting,
                name,
                str(window),
                str(len(group)),
                stat("severity_mae_faulted"),
                *(stat("per_class", f, "severity_mae", digits=2) for f in FAULTS),
                *(stat("by_severity", s, "severity_mae", digits=2) for s in levels),
                stat("accuracy", needs_head=False),
                stat("localisation_accuracy", needs_head=False),
            ]
            out.append("| " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])


def cost_markdown(rows: list[dict[str, Any]], root: Path) -> str:
    """Wall time per run (mean over seeds, where measured) and per block (``blocks.tsv``, which
    ``results/thesis_physics/command.sh`` appends to)."""
    out = ["### Cost: wall time per run and per block", ""]
    blocks = root / "blocks.tsv"
    if blocks.is_file():
        out += ["| block | wall s | parallel runs | host |", "|---|---|---|---|"]
        for line in blocks.read_text().splitlines():
            parts = line.split("\t")
            if len(parts) == 4:
                out.append("| " + " | ".join(parts) + " |")
        out.append("")
    timed = [r for r in rows if r["wall_seconds"][2]]
    if timed:
        out += ["| setting | variant | W | runs | s / run |", "|---|---|---|---|---|"]
        for r in timed:
            mean, std, n = r["wall_seconds"]
            cells = (r["setting"], r["variant"], r["window"], n, f"{mean:.0f} ± {std:.0f}")
            out.append("| " + " | ".join(map(str, cells)) + " |")
        total = sum(r["wall_seconds"][0] * r["wall_seconds"][2] for r in timed)
        out += [
            "",
            f"{sum(r['wall_seconds'][2] for r in timed)} runs, "
            f"{total / 3600:.2f} h of run time in all.",
            "",
        ]
    return "\n".join(out)


def markdown(rows: list[dict[str, Any]]) -> str:
    """Tables 6, 7 and 8, then every other setting in Table 6's layout."""
    parts = [t for t in (table6(rows), table7(rows), table8(rows)) if t]
    others = [r for r in rows if r["setting"] != REFERENCE and r["graph"] == "structural"]
    for setting in dict.fromkeys(r["setting"] for r in others):
        parts += [f"### {setting}", "", _MAIN_HEAD, "|---|---|---|---|---|---|---|---|---|---|---|"]
        parts += [_main_row(r) for r in others if r["setting"] == setting] + [""]
    return "\n".join(parts)


def write_csv(rows: list[dict[str, Any]]) -> str:
    buffer = io.StringIO()
    w = csv.writer(buffer)
    keys = [f"{d}.{m}" for d, m in COLUMNS]
    keys += ["gamma", "coupling_correlation", "best_epoch", "wall_seconds"]
    keys += [f"loc.{f}" for f in FAULTS]
    w.writerow(
        [
            "graph",
            "sensing",
            "placement",
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
                r["sensing"],
                r["placement"],
                r["variant"],
                r["window"],
                len(r["seeds"]),
                *[f"{v:.6g}" for k in keys for v in r[k][:2]],
            ]
        )
    return buffer.getvalue()


def visibility_markdown(runs: list[dict[str, Any]]) -> str:
    """What each model sees of each fault on the held-out session: recall per class, accuracy of
    faulted windows per severity, and on faulted windows whose faulted joint moved or stood
    still (friction acts only on a moving joint)."""
    strata = [("by_severity", s) for s in ("0.3", "0.6", "0.9")] + [
        ("by_motion", m) for m in ("moving", "still")
    ]
    head = [*FAULTS, *(f"sev. {s}" for _, s in strata[:3]), "moving", "still"]
    out = [
        "### Held-out recall per class, and accuracy by severity and by motion",
        "",
        "| setting | variant | W | " + " | ".join(head) + " |",
        "|---|---|---|" + "---|" * len(head),
    ]
    for key, members in grouped(runs):
        cells = [_fmt(_mean_std([_recall(m, c) for m in members])) for c in FAULTS]
        cells += [
            _fmt(_mean_std([_get(m, "heldout", group, name, "accuracy") for m in members]))
            for group, name in strata
        ]
        out.append(f"| {key[0]} | {key[1]} | {key[2]} | " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])
