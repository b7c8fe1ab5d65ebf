"""Commissioning with the z-scoring refitted to the unseen arm's healthy running, against the
commissioning that keeps the training arms' (``studies/arms/campaign.py --normalisation M``).

    python studies/arms/normalisation.py [--out outputs/campaign_seven] [--sensing full]
        [--seed 42] [--recipes commissioned_shift,commissioned30_hr0.99_shift,...]
        [--recall struct_weaken]

Per unseen arm and variant, each leave-one-arm-out model uncommissioned, commissioned as before
(``none``), and commissioned with ``sensors``, ``shift`` and ``moments``
(``deploy/renormalise.py``): accuracy and localisation on the unseen arm's training sessions
(validation: labelled running of that arm that no model here trained on) and on its held-out
session, and the commissioned network's false alarms over the arm's healthy hour where they
were counted. The recipe is chosen on validation alone, per variant and over all: the mean of
accuracy and localisation over the unseen arms. ``--recipes`` sets other commissioned
directories side by side instead (``campaign.py``'s names: a healthy rate, more minutes), and
``--recall C`` adds fault class C's recall on both splits.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from campaign import commissioned_dir  # this folder's campaign: where each model is written

from robohealth_mj.deploy.renormalise import MATCHES
from robohealth_mj.reporting.markdown import heading

ROOT = Path(__file__).resolve().parents[2]
RESULTS = Path(__file__).resolve().parent / "results"
RECIPES = {  # what each recipe's scores are read from, under a run
    "uncommissioned": ".",
    "commissioned": commissioned_dir(Path()).name,
    **{m: commissioned_dir(Path(), None, m).name for m in MATCHES if m != "none"},
}
TICK_S = 0.05


def _metrics(run: Path, split: str) -> dict | None:
    path = run / f"eval_{split}.json"
    return json.loads(path.read_text())["metrics"] if path.is_file() else None


def _false_alarms(done: Path) -> str:
    alarms = [json.loads(p.read_text()) for p in sorted(done.glob("alarms_*.json"))]
    if not alarms:
        return "–"
    hours = sum(a["settled_healthy_ticks"] for a in alarms) * TICK_S / 3600
    return f"{sum(a['false_alarms'] for a in alarms) / hours:.2f}"


def collect(
    root: Path, seed: int, recipes: dict[str, str] = RECIPES, recall: str | None = None
) -> list[dict]:
    """One row per (unseen arm, variant, recipe) of seed ``seed``'s models with validation and
    held-out scores."""
    rows = []
    for run in sorted(root.glob(f"*/**/w32/seed{seed}")):
        if not (run / "best.ckpt").is_file():
            continue
        arm, variant = run.relative_to(root).parts[0], run.parts[-3]
        for recipe, sub in recipes.items():
            done = run / sub
            val, held = _metrics(done, "validation"), _metrics(done, "heldout")
            if val is None or held is None:
                continue
            scores = {split: (m["accuracy"], m["localisation_accuracy"])
                      for split, m in (("val", val), ("heldout", held))}  # fmt: skip
            if recall:  # class ``recall``'s recall on both splits
                scores["recall"] = tuple(m["per_class"][recall]["recall"] for m in (val, held))
            rows.append({"arm": arm, "variant": variant, "recipe": recipe, **scores,
                         "false_alarms": _false_alarms(done)})  # fmt: skip
    return rows


def table(rows: list[dict], recall: str | None = None, what: str = "normalisation") -> str:
    extra = [f"validation {recall} recall", f"held-out {recall} recall"] if recall else []
    lines = heading(
        f"Leave-one-arm-out, the commissioning's {what} (unseen arm)",
        ["unseen arm", "variant", "recipe", "validation acc.", "validation loc.",
         "held-out acc.", "held-out loc.", *extra, "false alarms / healthy h"],
    )  # fmt: skip
    for r in rows:
        cells = [*r["val"], *r["heldout"], *r.get("recall", ())]
        scores = " | ".join(f"{v:.3f}" for v in cells)
        run = f"| {r['arm']} | {r['variant']} | {r['recipe']} |"
        lines.append(f"{run} {scores} | {r['false_alarms']} |")
    return "\n".join(lines) + "\n"


def _complete(rows: list[dict]) -> set[tuple[str, str]]:
    """The (arm, variant) pairs scored under every recipe found: the means compare like with
    like."""
    recipes: dict[tuple[str, str], set[str]] = {}
    for r in rows:
        recipes.setdefault((r["arm"], r["variant"]), set()).add(r["recipe"])
    found = {r["recipe"] for r in rows}
    return {key for key, got in recipes.items() if got == found}


def choice(rows: list[dict], recipes: dict[str, str] = RECIPES) -> str:
    """Each recipe's mean over the unseen arms, per variant and over all variants, and the pick
    of each: the best validation mean of accuracy and localisation."""
    complete, found = _complete(rows), [q for q in recipes if q in {r["recipe"] for r in rows}]
    lines = heading(
        f"Means over the unseen arms ({len(complete)} models); the pick is validation's",
        ["variant", "recipe", "validation acc.", "validation loc.", "validation mean",
         "held-out acc.", "held-out loc.", "picked"],
    )  # fmt: skip
    for variant in [*sorted({v for _, v in complete}), "all"]:
        means, cells = {}, {}
        for recipe in found:
            got = [
                r for r in rows
                if r["recipe"] == recipe and (r["arm"], r["variant"]) in complete
                and variant in ("all", r["variant"])
            ]  # fmt: skip
            val = np.mean([r["val"] for r in got], axis=0)
            held = np.mean([r["heldout"] for r in got], axis=0)
            means[recipe] = float(val.mean())
            cells[recipe] = (f"{val[0]:.3f} | {val[1]:.3f} | {val.mean():.3f} | {held[0]:.3f} | "
                             f"{held[1]:.3f}")  # fmt: skip
        best = max(means, key=means.get)
        for recipe in found:
            mark = "yes" if recipe == best else ""
            lines.append(f"| {variant} | {recipe} | {cells[recipe]} | {mark} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "outputs" / "campaign_seven")
    parser.add_argument("--sensing", default="full")
    parser.add_argument("--seed", type=int, default=42)
    parser.add_argument("--recipes", help="commissioned directories to compare, comma-separated")
    parser.add_argument("--recall", help="a fault class whose recall to add, e.g. struct_weaken")
    args = parser.parse_args()
    recipes = {r: r for r in args.recipes.split(",")} if args.recipes else RECIPES
    rows = collect(args.out / args.sensing / "loao", args.seed, recipes, args.recall)
    if not rows:
        raise SystemExit(f"no scored runs under {args.out / args.sensing / 'loao'}")
    what = "recipes" if args.recipes else "normalisation"
    print(table(rows, args.recall, what) + "\n" + choice(rows, recipes))


if __name__ == "__main__":
    main()
