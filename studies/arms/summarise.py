"""The cross-arm table from the campaign's evaluations (``studies/arms/campaign.py``).

    python studies/arms/summarise.py [--sensing full] [--out DIR] [--seeds 42]
        [--healthy-rate 0.99] [--normalisation shift] [--commissioning-minutes 30]
        [--against DIR] [--own DIR] [--baseline-normalisation none]

One row per held-out arm and variant: the arm's own model; the leave-one-arm-out model (trained
with ``transfer=true`` on the family's other arms) before and after commissioning on ten minutes
of the arm's healthy running; the commissioned network's false alarms over the arm's healthy
hour (the monitor's replay with its default alarm policy). Mean ± std over the seeds found.
Then each network against ``gbdt`` after commissioning: ahead when the difference of the means
exceeds the larger seed std (``--baseline-normalisation M``: ``gbdt``'s models commissioned with M,
each model by its own validation's recipe, e.g. ``shift`` for the networks and ``none`` for the
trees). Also writes ``studies/arms/results/results_<sensing>.csv`` (for another ``--out``,
``results_<its name>_<sensing>.csv``; ``--tag T``: ``results_<its name>_<T>_...``).
``--healthy-rate R`` reads the models commissioned at that healthy rate (``campaign.py
--healthy-rate R``) in place of validation's.
``--normalisation M`` reads the models commissioned with that normalisation
(``campaign.py --normalisation M``), ``--commissioning-minutes N`` those commissioned on N
healthy minutes. ``--against DIR`` adds each model beside the same model of
another campaign root (e.g. one trained on fewer sessions per arm): what the recipe changed, per
arm, variant and stage.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
from collections import defaultdict
from pathlib import Path

import numpy as np
from campaign import commissioned_dir  # this folder's campaign: where each model is written

from robohealth_mj.deploy.renormalise import MATCHES
from robohealth_mj.reporting.markdown import heading

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "outputs" / "campaign_arms"
RESULTS = Path(__file__).resolve().parent / "results"
ARMS = (
    "ur3e",
    "ur5e",
    "ur10e",
    "ur16e",
    "ur20",
    "ur30",
    "fr3",
    "fr3_current",
    "iiwa14",
    "gen3",
    "xarm7",
)  # the rows, where a campaign has them (fr3_current: the FR3 read from its currents)
TICK_S = 0.05


def _metrics(path: Path) -> dict | None:
    return json.loads(path.read_text())["metrics"] if path.is_file() else None


def collect(
    sensing: str,
    out: Path = OUT,
    seeds: set[str] | None = None,
    commissioned: str = "commissioned",
    own: Path | None = None,
) -> dict[tuple[str, str], dict[str, list[float]]]:
    """``(arm, variant) -> {column: [one value per seed]}`` (``seeds``: only these, e.g.
    ``{"42"}``, to set one seed of two campaigns side by side; ``commissioned``: the directory
    of the commissioned models to read; ``own``: the campaign root of the arms' own models,
    default ``out``)."""
    table: dict[tuple[str, str], dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))
    for stage, root in (("own", own or out), ("loao", out)):
        for ev in sorted((root / sensing / stage).glob("*/**/seed*/eval_heldout.json")):
            run = ev.parent
            if seeds is not None and run.name.removeprefix("seed") not in seeds:
                continue
            arm = run.relative_to(root / sensing / stage).parts[0]
            variant = run.parts[-3]
            row = table[(arm, variant)]
            m = _metrics(ev)
            row[f"{stage}_acc"].append(m["accuracy"])
            row[f"{stage}_loc"].append(m["localisation_accuracy"])
            summary = json.loads((run / "train_summary.json").read_text())
            best = summary["history"][summary["best_epoch"] - 1]
            row[f"{stage}_val_acc"].append(best["val_accuracy"])
            row[f"{stage}_val_loc"].append(best["val_localisation"])
            row[f"{stage}_train_s"].append(summary["train_seconds"])
            row[f"{stage}_epochs"].append(summary["epochs"])
            row[f"{stage}_selected"].append(selected(best, summary["best_epoch"]))
            after = _metrics(run / commissioned / "eval_heldout.json")
            if stage == "loao" and after is not None:
                row["after_acc"].append(after["accuracy"])
                row["after_loc"].append(after["localisation_accuracy"])
            alarms = [
                json.loads(p.read_text()) for p in sorted(run.glob(f"{commissioned}/alarms_*.json"))
            ]
            if stage == "loao" and alarms:
                hours = sum(a["settled_healthy_ticks"] for a in alarms) * TICK_S / 3600
                row["false_alarms_per_hour"].append(sum(a["false_alarms"] for a in alarms) / hours)
                row["healthy_hours"].append(hours)
    return table


def selected(best: dict, best_epoch: int) -> int:
    """What validation selected: the best epoch of a network, the class booster's rounds of
    ``gbdt`` (early stopping on the validation split)."""
    boosting = best.get("boosting")
    return int(boosting["class"]["best_iteration"]) if boosting else int(best_epoch)


def _cell(values: list[float], digits: int = 3) -> str:
    if not values:
        return "–"
    if len(values) == 1:
        return f"{values[0]:.{digits}f}"
    return f"{np.mean(values):.{digits}f} ± {np.std(values):.{digits}f}"


COLUMNS = ("own_acc", "own_loc", "loao_acc", "loao_loc", "after_acc", "after_loc",
           "false_alarms_per_hour", "healthy_hours")  # fmt: skip


def markdown(table: dict, sensing: str) -> str:
    lines = heading(
        f"Cross-arm, sensing = {sensing} (held-out session of each arm, W = 32)",
        ["arm", "variant", "seeds (own / unseen)", "own acc.", "own loc.", "unseen acc.",
         "unseen loc.", "commissioned acc.", "commissioned loc.", "Δ acc. vs own",
         "Δ loc. vs own", "false alarms / healthy h"],
    )  # fmt: skip
    for arm in ARMS:
        for variant in sorted({v for a, v in table if a == arm}):
            r = table[(arm, variant)]
            seeds = f"{len(r['own_acc'])} / {len(r['loao_acc'])}"
            gap = [
                _cell([np.mean(r[f"after_{k}"]) - np.mean(r[f"own_{k}"])])
                if r[f"after_{k}"] and r[f"own_{k}"]
                else "–"
                for k in ("acc", "loc")
            ]
            hours = f" ({np.mean(r['healthy_hours']):.2f} h)" if r["healthy_hours"] else ""
            lines.append(
                f"| {arm} | {variant} | {seeds} | {_cell(r['own_acc'])} | {_cell(r['own_loc'])} | "
                f"{_cell(r['loao_acc'])} | {_cell(r['loao_loc'])} | {_cell(r['after_acc'])} | "
                f"{_cell(r['after_loc'])} | {gap[0]} | {gap[1]} | "
                f"{_cell(r['false_alarms_per_hour'], 2)}{hours} |"
            )
    return "\n".join(lines) + "\n"


def validation(table: dict, sensing: str) -> str:
    """What selection may read: each leave-one-arm-out model's run-aware validation split of its
    three training arms (at its best epoch), beside the unseen arm it is then scored on."""
    lines = heading(
        f"Validation (the training arms' split) and the unseen arm, sensing = {sensing}",
        ["unseen arm", "variant", "epochs", "selected (epoch; gbdt: rounds)", "validation acc.",
         "validation loc.", "unseen acc.", "unseen loc.", "train s / run"],
    )  # fmt: skip
    for arm in ARMS:
        for variant in sorted({v for a, v in table if a == arm}):
            r = table[(arm, variant)]
            if not r["loao_val_acc"]:
                continue
            epochs = "/".join(str(e) for e in sorted(set(r["loao_epochs"])))
            lines.append(
                f"| {arm} | {variant} | {epochs} | {_cell(r['loao_selected'], 0)} | "
                f"{_cell(r['loao_val_acc'])} | "
                f"{_cell(r['loao_val_loc'])} | {_cell(r['loao_acc'])} | {_cell(r['loao_loc'])} | "
                f"{np.mean(r['loao_train_s']):.0f} |"
            )
    return "\n".join(lines) + "\n"


def verdict(
    table: dict, sensing: str, baseline: str = "gbdt", baseline_table: dict | None = None
) -> str:
    """The issue's question in one table: each network against the trees on the unseen arm
    after commissioning, the difference of the means beside the larger of the two seed stds
    (the trees' rows from ``baseline_table`` where they were commissioned another way)."""
    lines = heading(
        f"The graph against `{baseline}` on the unseen arm after commissioning, "
        f"sensing = {sensing}",
        ["arm", "variant", f"Δ acc. vs {baseline}", "larger std", "ahead",
         f"Δ loc. vs {baseline}", "larger std", "ahead"],
    )  # fmt: skip
    for arm in ARMS:
        base = (baseline_table or table).get((arm, baseline))
        for variant in sorted(v for a, v in table if a == arm and v != baseline):
            cells = []
            for k in ("acc", "loc"):
                ours, theirs = table[(arm, variant)][f"after_{k}"], (base or {}).get(f"after_{k}")
                if not ours or not theirs:
                    cells += ["–", "–", "–"]
                    continue
                gap, spread = np.mean(ours) - np.mean(theirs), max(np.std(ours), np.std(theirs))
                if min(len(ours), len(theirs)) < 2:  # one seed has no spread to beat
                    cells += [f"{gap:+.3f}", "one seed", "–"]
                    continue
                cells += [f"{gap:+.3f}", f"{spread:.3f}", "yes" if gap > spread else "no"]
            lines.append(f"| {arm} | {variant} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def against(table: dict, base: dict, sensing: str, base_name: str) -> str:
    """Each model of this campaign beside the same model of ``base`` (another recipe): its
    own model on its held-out session, and the leave-one-arm-out model after commissioning."""
    lines = heading(
        f"This campaign against `{base_name}`, sensing = {sensing} (held-out session; seeds)",
        ["arm", "variant", "stage", f"{base_name} acc.", f"{base_name} loc.", "this acc.",
         "this loc.", "Δ acc.", "Δ loc."],
    )  # fmt: skip
    for arm in ARMS:
        for variant in sorted({v for a, v in table if a == arm}):
            r, b = table[(arm, variant)], base.get((arm, variant), {})
            for stage, key in (("own", "own"), ("unseen, commissioned", "after")):
                ours = [r[f"{key}_acc"], r[f"{key}_loc"]]
                if not ours[0]:
                    continue
                theirs = [b.get(f"{key}_acc", []), b.get(f"{key}_loc", [])]
                gaps = [
                    f"{np.mean(o) - np.mean(t):+.3f}" if t else "–"
                    for o, t in zip(ours, theirs, strict=True)
                ]
                lines.append(
                    f"| {arm} | {variant} | {stage} | {_cell(theirs[0])} ({len(theirs[0])}) | "
                    f"{_cell(theirs[1])} | {_cell(ours[0])} ({len(ours[0])}) | "
                    f"{_cell(ours[1])} | {gaps[0]} | {gaps[1]} |"
                )
    return "\n".join(lines) + "\n"


def write_csv(table: dict, path: Path) -> None:
    buffer = io.StringIO()
    w = csv.writer(buffer)
    w.writerow(["arm", "variant", *[f"{c}_{s}" for c in COLUMNS for s in ("mean", "std", "n")]])
    for (arm, variant), r in sorted(table.items()):
        cells = []
        for c in COLUMNS:
            v = r[c]
            cells += [f"{np.mean(v):.6g}", f"{np.std(v):.6g}", len(v)] if v else ["", "", 0]
        w.writerow([arm, variant, *cells])
    path.write_text(buffer.getvalue())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sensing", default="full")
    parser.add_argument("--out", type=Path, default=OUT, help="campaign root")
    parser.add_argument(
        "--tag", help="a word in the CSV's name, so that a run of a few arms keeps the others' CSV"
    )
    parser.add_argument("--seeds", help="only these seeds, e.g. 42 or 42,43 (default: all found)")
    parser.add_argument(
        "--healthy-rate", type=float, help="the models commissioned at this healthy rate"
    )
    parser.add_argument(
        "--normalisation",
        default="none",
        choices=MATCHES,
        help="the models commissioned with this normalisation (campaign.py --normalisation M)",
    )
    parser.add_argument(
        "--commissioning-minutes",
        type=int,
        default=10,
        help="the models commissioned on this many healthy minutes (campaign.py, same option)",
    )
    parser.add_argument(
        "--against", type=Path, help="another campaign root to set each model beside"
    )
    parser.add_argument(
        "--baseline-normalisation",
        choices=MATCHES,
        help="compare against gbdt commissioned with this normalisation (default: --normalisation)",
    )
    parser.add_argument(
        "--own",
        type=Path,
        help="the campaign root of the arms' own models (default --out), e.g. the seven-joint "
        "campaign's for the family's leave-one-arm-out",
    )
    parser.add_argument(
        "--as-trained",
        action="store_true",
        help="the unseen arm's models as trained, not commissioned, in the commissioned columns "
        "(with their alarms where campaign.py counted them): for a campaign whose training saw "
        "some of the arm's own sessions (campaign.py --unseen-sessions)",
    )
    args = parser.parse_args()
    seeds = set(args.seeds.split(",")) if args.seeds else None
    rate = args.healthy_rate
    minutes = args.commissioning_minutes
    commissioned = commissioned_dir(Path(), rate, args.normalisation, minutes).name
    commissioned = "." if args.as_trained else commissioned
    table = collect(args.sensing, args.out, seeds, commissioned, args.own)
    if not table:
        raise SystemExit(f"no evaluations under {args.out / args.sensing}: run the campaign first")
    RESULTS.mkdir(parents=True, exist_ok=True)
    recipe = "" if args.out.resolve() == OUT.resolve() else f"{args.out.name}_"
    recipe += f"{args.tag}_" if args.tag else ""
    recipe += f"seeds{'_'.join(sorted(seeds))}_" if seeds else ""
    recipe += f"{minutes}min_" if minutes != 10 else ""
    recipe += f"hr{rate:g}_" if rate is not None else ""
    recipe += f"{args.normalisation}_" if args.normalisation != "none" else ""
    recipe += "as_trained_" if args.as_trained else ""
    write_csv(table, RESULTS / f"results_{recipe}{args.sensing}.csv")
    print(markdown(table, args.sensing))
    base_norm = args.baseline_normalisation or args.normalisation
    base_dir = "." if args.as_trained else commissioned_dir(Path(), rate, base_norm, minutes).name
    trees = (
        table
        if base_dir == commissioned
        else collect(args.sensing, args.out, seeds, base_dir, args.own)
    )
    if any(v == "gbdt" for _, v in trees):
        print(verdict(table, args.sensing, baseline_table=trees))
    print(validation(table, args.sensing))
    if args.against is not None:
        base = collect(args.sensing, args.against, seeds, commissioned)
        print(against(table, base, args.sensing, args.against.name))


if __name__ == "__main__":
    main()
