"""The cost frontier's table and plot: each form's quality (validation, held-out, probe; mean and
std over seeds, through onnxruntime) beside what it costs (MFLOP per stream-tick, streams
sustained), from the runner's outputs.

    python studies/cost_frontier/summarise.py outputs/cost_frontier studies/cost_frontier/results

A later pass that measures a few forms again (one or more bench runs: each model's median)
writes its own table beside the first (``--bench``, ``--scores``, ``--name``); its on-line rows
are those of its forms.
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numpy as np

from robohealth_mj.benchmarks.fleet import model_flops
from robohealth_mj.common.atomic import atomic_write_text

HEADLINE = "h64"
FILES = {
    "model.onnx": "float",
    "model_int8d.onnx": "int8 dynamic",
    "model_int8s.onnx": "int8 static",
}
CHANGES = {
    "h64": "the headline: anomaly_residual, W = 32, hidden 64, snapshot MLP 16, 2 layers",
    "h32": "hidden 32",
    "h16": "hidden 16",
    "h16c8": "hidden 16, snapshot MLP 8",
    "h16_kd": "hidden 16, distilled from the headline",
    "h16c8_kd": "hidden 16, snapshot MLP 8, distilled from the headline",
    "h64_l1": "one message-passing layer",
    "h16_w16": "hidden 16, W = 16",
    "h64s": "no snapshot-MLP record of the window's oldest snapshot (one record a sample)",
}
ONLINE_ENTRY = re.compile(r"^(.+)_k(\d+)(?:_s(\d+))?$")  # form, k, seed (absent: 42)
BENCH_ROW = re.compile(r"^\| (\S+) \| ([\d.]+) \| [\d.]+ \| (\d+) \| [\d.]+ \|$")


def bench_rows(paths: list[Path]) -> dict[tuple[str, str, int], dict]:
    """``(form, file kind, k) -> {mflop, sustained}`` from ``bench streams --compare``'s tables
    (``k``: the model run every k-th tick); with several runs, each model's median sustained."""
    out: dict[tuple[str, str, int], dict] = {}
    for path in paths:
        if not path.is_file():
            continue
        for line in path.read_text().splitlines():
            m = BENCH_ROW.match(line)
            if m:
                file, _, every = m.group(1).partition("@")
                model = Path(file)
                key = (model.parent.parent.name, FILES[model.name], int(every or 1))
                # MFLOP counted again: the int8 products were left out of the counter at first
                mflop = (
                    model_flops(str(model)) / 1e6 / key[2] if model.is_file() else float(m.group(2))
                )
                row = out.setdefault(key, {"mflop": mflop, "runs": []})
                row["runs"].append(int(m.group(3)))
    for row in out.values():
        row["sustained"] = int(np.median(row["runs"]))
    return out


def online_rows(results: Path, bench: dict, forms: set[str]) -> str:
    """The monitor's on-line figures per (form, k), beside the bench's cost: the selection
    session and the healthy hour (what a choice may be made on), then the held-out session."""

    def read(entry: str, name: str) -> dict:
        path = results / "online" / f"{entry}_{name}.json"
        return json.loads(path.read_text()) if path.is_file() else {}

    def alarms(d: dict) -> str:
        if not d:
            return "– | –"
        a = d["alarms"]
        return (
            f"{a['detected']} / {a['episodes']}, {d['false_alarms']} false | "
            f"{a['class_latency_s_median']:.2f} / {a['class_latency_s_p90']:.2f}"
        )

    lines = [
        "| form | seed | model every k ticks | MFLOP per stream-tick | sustained streams | "
        "selection session: episodes detected | latency to class, median / p90 s | healthy hour: "
        "false alarms per hour | selection on-line accuracy | held-out session: episodes "
        "detected | latency to class, median / p90 s | held-out on-line accuracy / localisation |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    entries = sorted({p.stem.rsplit("_", 1)[0] for p in (results / "online").glob("*.json")})
    for entry in entries:
        form, k, seed = ONLINE_ENTRY.match(entry).groups()
        if form not in forms:
            continue
        b = bench.get((form, "float", int(k)), {}) if seed is None else {}
        healthy, held = read(entry, "healthy"), read(entry, "heldout")
        selection = read(entry, "selection")
        rate = healthy.get("false_alarms_per_hour", float("nan"))
        accuracy = (
            f"{held['online_accuracy']:.3f} / {held['localisation_accuracy']:.3f}" if held else "–"
        )
        mflop = f"{b['mflop']:.3f}" if b else "–"
        lines.append(
            f"| {form} | {seed or 42} | {k} | {mflop} | {b.get('sustained', '–')} | "
            f"{alarms(selection)} | {rate:.2f} | {selection.get('online_accuracy', 0):.3f} | "
            f"{alarms(held)} | {accuracy} |"
        )
    return "\n".join(lines) + "\n"


def gbdt_row(root: Path, ref: dict[str, list[float]]) -> str | None:
    """``gbdt`` beside the networks (its checkpoint's own evaluation: trees have no ONNX form,
    so no fleet cost), when the runner's gbdt part has run."""
    run = root / "gbdt" / "seed42"
    if not (run / "eval_probe.json").is_file():
        return None
    summary = json.loads((run / "train_summary.json").read_text())
    val = summary["history"][summary["best_epoch"] - 1]
    held, probe = (json.loads((run / f"eval_{n}.json").read_text())["metrics"]
                   for n in ("heldout", "probe"))  # fmt: skip
    delta = " / ".join(
        f"{100 * (held[k] - np.mean(ref[f'heldout_{m}'])):+.1f}"
        for k, m in (("accuracy", "acc"), ("localisation_accuracy", "loc"))
    )
    return (
        f"| gbdt | gradient-boosted trees (the reference; no ONNX form) | trees | 1 | – | – | "
        f"{val['val_accuracy']:.3f} / {val['val_localisation']:.3f} | {held['accuracy']:.3f} / "
        f"{held['localisation_accuracy']:.3f} | {delta} | {probe['accuracy']:.3f} / "
        f"{probe['localisation_accuracy']:.3f} | {summary['train_seconds']:.0f} |"
    )


def quality(scores_path: Path) -> dict[tuple[str, str], dict[str, list[float]]]:
    """``(form, file kind) -> {set_metric: [per seed]}`` from ``score.py``'s file, plus train s."""
    scores = json.loads(scores_path.read_text())
    out: dict[tuple[str, str], dict[str, list[float]]] = {}
    for key, row in sorted(scores.items()):
        model, data = key.split("::")
        path = Path(model)
        form, kind = path.parent.parent.name, FILES[path.name]
        seeds = out.setdefault((form, kind), {})
        m = row["metrics"]
        seeds.setdefault(f"{data}_acc", []).append(m["accuracy"])
        seeds.setdefault(f"{data}_loc", []).append(m["localisation_accuracy"])
        if data == "heldout" and kind == "float":
            summary = json.loads((path.parent / "train_summary.json").read_text())
            seeds.setdefault("train_s", []).append(summary["train_seconds"])
    return out


def cell(values: list[float] | None, digits: int = 3) -> str:
    if not values:
        return "–"
    if len(values) == 1:
        return f"{values[0]:.{digits}f}"
    return f"{np.mean(values):.{digits}f} ± {np.std(values):.{digits}f}"


def table(q: dict, bench: dict, root: Path) -> str:
    ref = q[(HEADLINE, "float")]
    ref_bench = bench.get((HEADLINE, "float", 1), {})
    lines = [
        "| form | what changed | weights | seeds | MFLOP per stream-tick (x headline) | sustained "
        "streams (x headline) | validation acc. / loc. | held-out acc. / loc. | held-out "
        "minus headline (points) | probe acc. / loc. | train s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    order = [f for f in CHANGES if any(k[0] == f for k in q)]
    for form in order:
        for kind in FILES.values():
            seeds = q.get((form, kind))
            if not seeds:
                continue
            b = bench.get((form, kind, 1)) or bench.get((form.removesuffix("_kd"), kind, 1), {})
            cost = (
                f"{b['mflop']:.3f} ({b['mflop'] / ref_bench['mflop']:.2f})"
                if b and ref_bench
                else "–"
            )
            streams = (
                f"{b['sustained']} ({b['sustained'] / ref_bench['sustained']:.2f})"
                if b and ref_bench
                else "–"
            )
            delta = " / ".join(
                f"{100 * (np.mean(seeds[f'heldout_{k}']) - np.mean(ref[f'heldout_{k}'])):+.1f}"
                for k in ("acc", "loc")
            )
            lines.append(
                f"| {form} | {CHANGES[form]} | {kind} | {len(seeds['heldout_acc'])} | {cost} | "
                f"{streams} | {cell(seeds.get('val_acc'))} / {cell(seeds.get('val_loc'))} | "
                f"{cell(seeds['heldout_acc'])} / {cell(seeds['heldout_loc'])} | {delta} | "
                f"{cell(seeds.get('probe_acc'))} / {cell(seeds.get('probe_loc'))} | "
                f"{cell(seeds.get('train_s'), 0)} |"
            )
    reference = gbdt_row(root, ref)
    return "\n".join(lines + ([reference] if reference else [])) + "\n"


def plot(q: dict, bench: dict, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    markers = {"float": "o", "int8 dynamic": "s", "int8 static": "^"}
    for (form, kind), seeds in sorted(q.items()):
        b = bench.get((form, kind, 1)) or bench.get((form.removesuffix("_kd"), kind, 1))
        if not b:
            continue
        for ax, metric, name in zip(
            axes, ("acc", "loc"), ("accuracy", "localisation"), strict=True
        ):
            values = seeds[f"heldout_{metric}"]
            ax.errorbar(b["mflop"], np.mean(values), yerr=np.std(values), fmt=markers[kind],
                        capsize=3, color="C3" if form == HEADLINE else "C0")  # fmt: skip
            ax.annotate(f"{form}{'' if kind == 'float' else ' ' + kind.split()[1]}",
                        (b["mflop"], np.mean(values)), fontsize=6, textcoords="offset points",
                        xytext=(4, 3))  # fmt: skip
            ax.set_ylabel(f"held-out {name} (mean ± std over seeds)")
    for (form, kind, k), b in sorted(bench.items()):  # the same model every k-th tick
        seeds = q.get((form, kind))
        if k == 1 or not seeds:
            continue
        for ax, metric in zip(axes, ("acc", "loc"), strict=True):
            values = seeds[f"heldout_{metric}"]
            ax.errorbar(b["mflop"], np.mean(values), yerr=np.std(values), fmt="D", capsize=3,
                        color="C2")  # fmt: skip
            ax.annotate(f"{form}@{k}", (b["mflop"], np.mean(values)), fontsize=6,
                        textcoords="offset points", xytext=(4, -9))  # fmt: skip
    ref = q[(HEADLINE, "float")]
    for ax, metric in zip(axes, ("acc", "loc"), strict=True):
        ax.axhline(np.mean(ref[f"heldout_{metric}"]) - 0.01, ls="--", lw=0.8, color="grey")
        ax.set_xscale("log")
        ax.set_ylim(0.82, 0.885)  # int8 static (0.69 / 0.73) lies below: results/frontier.md
        ax.set_xlabel("MFLOP per stream-tick (log)")
        ax.grid(alpha=0.3)
    ref_mflop = bench.get((HEADLINE, "float", 1), {}).get("mflop")
    if ref_mflop:
        for ax in axes:
            ax.axvline(ref_mflop / 4, ls=":", lw=0.8, color="grey")
    fig.suptitle(
        "Cost frontier (streams sustained: results/frontier.md). Dashed: 1 point under the "
        "headline; dotted: 1/4 of its MFLOP; green: the same model every k ticks (@k)",
        fontsize=9,
    )
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", type=Path)
    parser.add_argument("results", type=Path)
    parser.add_argument("--bench", nargs="+", default=["bench_compare.txt"],
                        help="in results; several: each model's median")  # fmt: skip
    parser.add_argument("--scores", default="scores.json", help="in root")
    parser.add_argument("--name", default="frontier", help="results/NAME.md and NAME.png")
    args = parser.parse_args()
    q = quality(args.root / args.scores)
    bench = bench_rows([args.results / name for name in args.bench])
    out = args.results / f"{args.name}.md"
    atomic_write_text(
        out,
        "## Quality and cost of each form\n\n" + table(q, bench, args.root)
        + "\n## The model every k ticks: on-line figures (each seed's model), cost (seed 42's)\n\n"
        + online_rows(args.results, bench, {form for form, _ in q}),
    )  # fmt: skip
    plot(q, bench, args.results / f"{args.name}.png")
    print(out.read_text())


if __name__ == "__main__":
    main()
