"""Which sessions may validate a model for an arm it never trained on? (issue 65)

    python studies/arms/validation_sessions.py [--out DIR] [--seeds 42,43,44]
        [--recipes uncommissioned,commissioned_shift,...]
    python studies/arms/validation_sessions.py --per-session RUN [RUN ...]

A corpus seed gives every arm of one joint count the same program and fault schedule (the
recorder draws them from the seed and the joint count alone), so an unseen seven-joint arm's
training sessions, seeds 100-107, replay what the other seven-joint arms' sessions of those seeds
trained on. They used to validate the leave-one-arm-out models. ``campaign.py --steps validate``
now scores on the arm's ``validation_seed500`` and ``501`` instead (training's distribution,
programmes no arm trains on) and keeps the old scores as ``eval_validation_shared_programme.json``.
Per unseen arm, variant and recipe (means over the seeds found): both validations beside the
held-out session, and the recipe each validation picks for that arm and variant (the best mean
of accuracy and localisation). ``--per-session`` scores each of a run's unseen-arm training
sessions alone, beside whether the run trained on that seed's program, on this arm or another
(its run-aware split holds some seeds out whole, for early stopping and its own test).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from normalisation import RECIPES  # this folder's: recipe name -> directory under a run

from robohealth_mj.data.windows import session_of
from robohealth_mj.learn.evaluation import evaluate_checkpoint
from robohealth_mj.reporting.markdown import heading

SPLITS = {
    "shared": "validation_shared_programme",
    "fresh": "validation",
    "held-out": "heldout",
}


def scores(done: Path) -> dict[str, tuple[float, float]] | None:
    """Split -> (accuracy, localisation) of one scored model (NaN for a shared-programme
    validation never run), or None where fresh validation or held-out is missing."""
    out = {}
    for name, split in SPLITS.items():
        path = done / f"eval_{split}.json"
        if not path.is_file():
            if name != "shared":
                return None
            out[name] = (float("nan"), float("nan"))
            continue
        m = json.loads(path.read_text())["metrics"]
        out[name] = (m["accuracy"], m["localisation_accuracy"])
    return out


def cell(pair: np.ndarray) -> str:
    return "–" if np.isnan(pair).any() else f"{pair[0]:.3f} / {pair[1]:.3f}"


def collect(root: Path, seeds: list[int], recipes: dict[str, str]) -> dict[tuple, list[dict]]:
    """(arm, variant, recipe) -> the scores of each seed with fresh validation and held-out."""
    rows: dict[tuple, list[dict]] = {}
    for seed in seeds:
        for run in sorted(root.glob(f"*/**/w32/seed{seed}")):
            if not (run / "best.ckpt").is_file():
                continue
            arm, variant = run.relative_to(root).parts[0], run.parts[-3]
            for recipe, sub in recipes.items():
                got = scores(run / sub)
                if got is not None:
                    rows.setdefault((arm, variant, recipe), []).append(got)
    return rows


def trained_sessions(run: Path) -> set[str]:
    """The sessions (program and fault schedule) the run trained on, on any arm."""
    split = json.loads((run / "train_summary.json").read_text())["split_runs"]
    return {session_of(r) for r in split["train"]}


def per_session(runs: list[Path]) -> None:
    """Each training session of the run's unseen arm scored alone, by whether its seed trained."""
    lines = heading(
        "The unseen arm's training sessions, one at a time",
        ["run", "session", "its program in training", "accuracy", "localisation"],
    )
    for run in runs:
        held = json.loads((run / "eval_heldout.json").read_text())["data"][0]
        arm_dir, trained = Path(held).parents[1], trained_sessions(run)
        for session in sorted(arm_dir.glob("train_*")):
            run_id = json.loads((session / "manifest.json").read_text())["recording_run_id"]
            seen = session_of(run_id) in trained
            m = evaluate_checkpoint(run / "best.ckpt", str(session), "cpu")["metrics"]
            lines.append(f"| {run} | {session.name} | {'yes' if seen else 'no'} | "
                         f"{m['accuracy']:.3f} | {m['localisation_accuracy']:.3f} |")  # fmt: skip
    print("\n".join(lines))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("outputs/campaign_family_plus2"))
    parser.add_argument("--sensing", default="full")
    parser.add_argument("--seeds", default="42,43,44")
    parser.add_argument("--recipes", default="uncommissioned,commissioned_shift,commissioned")
    parser.add_argument("--per-session", nargs="+", type=Path, metavar="RUN")
    args = parser.parse_args()
    if args.per_session:
        per_session(args.per_session)
        return
    named = {**RECIPES, **{r: r for r in args.recipes.split(",") if r not in RECIPES}}
    recipes = {r: named[r] for r in args.recipes.split(",")}
    rows = collect(args.out / args.sensing / "loao", [int(s) for s in args.seeds.split(",")],
                   recipes)  # fmt: skip
    lines = heading(
        f"Validation on shared and on fresh programmes ({args.out}, seeds {args.seeds})",
        ["unseen arm", "variant", "recipe", "seeds", "shared-programme validation acc. / loc.",
         "fresh validation acc. / loc.", "held-out acc. / loc.", "picked: shared / fresh"],
    )  # fmt: skip
    pairs = sorted({(arm, variant) for arm, variant, _ in rows})
    for arm, variant in pairs:
        here = {r: v for (a, m, r), v in rows.items() if (a, m) == (arm, variant)}
        means = {r: {s: np.mean([v[s] for v in runs], axis=0) for s in SPLITS}
                 for r, runs in here.items()}  # fmt: skip
        picks = {}
        for s in ("shared", "fresh"):
            scored = {r: float(m[s].mean()) for r, m in means.items() if not np.isnan(m[s]).any()}
            picks[s] = max(scored, key=scored.get) if len(scored) > 1 else None
        for recipe, m in means.items():
            cells = " | ".join(cell(m[s]) for s in SPLITS)
            mark = " / ".join("yes" if picks[s] == recipe else "–" for s in ("shared", "fresh"))
            lines.append(
                f"| {arm} | {variant} | {recipe} | {len(here[recipe])} | {cells} | {mark} |"
            )
    print("\n".join(lines))


if __name__ == "__main__":
    main()
