"""The tables of ``studies/coupling_sign/results/results.md`` from the runs (issue 69).

    python studies/coupling_sign/summarise.py [--root outputs/coupling_sign] [--out FILE]
    python studies/coupling_sign/summarise.py --grid FILE | --epochs FILE   (from results/runs)

Reads this study's runs (``run.sh``: the motion-fitted coupling, ``model.coupling_fit=motion``),
the thesis rerun's committed runs of the same recipe with the coupling every loss trains
(``studies/thesis_physics/results/runs/harness``: ``losses``) and ``gbdt`` beside them, and the
placement fits without training (``results/fits.json``). Validation figures are the best
epoch's (what selection saw); held-out figures are the standard held-out session's.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_text

THESIS = Path("studies/thesis_physics/results/runs/harness")
FITS = Path("studies/coupling_sign/results/fits.json")
ARCHIVE = Path("studies/coupling_sign/results/runs")  # run.sh archive: the grid's run records
RECIPE = "anomaly_residual_motion_joint"


def run_row(run: Path) -> dict | None:
    """One run's figures, or None when it has not finished."""
    try:
        summary = json.loads((run / "train_summary.json").read_text())
        heldout = json.loads((run / "eval_heldout.json").read_text())["metrics"]
    except FileNotFoundError:
        return None
    best = {h["epoch"]: h for h in summary.get("history") or []}.get(summary["best_epoch"], {})
    return {
        "val_acc": best.get("val_accuracy"),
        "val_loc": best.get("val_localisation"),
        "acc": heldout["accuracy"],
        "loc": heldout["localisation_accuracy"],
        "corr": summary.get("coupling_correlation"),
        "seconds": summary.get("wall_seconds"),
    }


def mean_std(values: list[float | None]) -> str:
    v = np.array([x for x in values if x is not None], float)
    if not len(v):
        return "–"
    return f"{v.mean():.3f}" if len(v) == 1 else f"{v.mean():.3f} ± {v.std(ddof=1):.3f}"


def table(rows: list[tuple[str, list[dict]]]) -> list[str]:
    out = [
        "| run | n | val acc | val loc | held-out acc | held-out loc | corr(C, C0) | s / run |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, runs in rows:
        if not runs:
            continue
        cols = [mean_std([r[k] for r in runs]) for k in ("val_acc", "val_loc", "acc", "loc")]
        corr = mean_std([r["corr"] for r in runs])
        secs = np.mean([r["seconds"] or 0 for r in runs])
        out.append(f"| {name} | {len(runs)} | {' | '.join(cols)} | {corr} | {secs:.0f} |")
    return out


def runs_of(pattern: str, root: Path) -> list[dict]:
    return [r for p in sorted(root.glob(pattern)) if (r := run_row(p)) is not None]


def fits_section() -> list[str]:
    if not FITS.is_file():
        return ["(no placement fits: run `bash studies/coupling_sign/run.sh fits`)"]
    fits = json.loads(FITS.read_text())["fits"]
    corr = np.array([f["coupling_correlation"] for f in fits])
    rows = np.array([f["rows"] for f in fits])
    per_row = ", ".join(
        f"joint {j + 1} {rows[:, j].mean():.2f} / {rows[:, j].min():.2f}"
        for j in range(rows.shape[1])
    )
    lines = [
        f"{len(fits)} fits (placements × profiles × split seeds): corr(C, C0) mean "
        f"{corr.mean():.3f}, min {corr.min():.3f}, max {corr.max():.3f}; "
        f"sign wrong (≤ 0) in {(corr <= 0).sum()}; below 0.9 in {(corr < 0.9).sum()}.",
        f"Per joint row (mean / min over the fits): {per_row}.",
        "",
    ]
    profiles = list(dict.fromkeys(f["sensing"] for f in fits))
    lines += [
        "| placement | " + " | ".join(f"{p}: corr per split seed" for p in profiles) + " |",
        "|---|" + "---|" * len(profiles),
    ]
    for placement in dict.fromkeys(f["placement"] for f in fits):
        by = [
            " ".join(
                f"{f['coupling_correlation']:.3f}"
                for f in fits
                if f["placement"] == placement and f["sensing"] == profile
            )
            for profile in profiles
        ]
        lines.append(f"| {placement} | {' | '.join(by)} |")
    return lines


def grid_section(archive: Path) -> list[str]:
    """Every placement x profile of the archived grid: corr(C, C0) of the run's coupling, and
    localisation of the recipe (motion fit + joint scores) beside ``gbdt`` on the same split, then
    per profile the distribution over placements."""
    lines = []
    for pr in ("full", "retrofit"):
        rows, deltas, corrs, wins = [], [], [], []
        for place in sorted(
            (archive / pr).glob("seed*"), key=lambda p: int(p.name[4:].split("_")[0])
        ):
            trees, ours = runs_of("gbdt/seed*", place), runs_of(f"{RECIPE}/seed*", place)
            if not ours:
                continue
            corr = [r["corr"] for r in ours if r["corr"] is not None]
            corrs += corr
            cells = [mean_std([r[k] for r in runs]) for runs in (trees, ours)
                     for k in ("val_loc", "loc")]  # fmt: skip
            delta = "–"
            if trees:
                d = 100 * (np.mean([r["loc"] for r in ours]) - np.mean([r["loc"] for r in trees]))
                v = np.mean([r["val_loc"] for r in ours]) - np.mean([r["val_loc"] for r in trees])
                deltas.append(d)
                wins.append(v >= 0)
                delta = f"{d:+.1f}"
            rows.append(f"| {place.name} | {len(ours)} | {mean_std(corr)} | {' | '.join(cells)} "
                        f"| {delta} |")  # fmt: skip
        if not rows:
            continue
        c = np.array(corrs)
        versus = (
            f"Held-out localisation minus gbdt's: mean {np.mean(deltas):+.1f} points, min "
            f"{np.min(deltas):+.1f}; the recipe level or ahead on validation in {sum(wins)} of "
            f"{len(wins)}."
            if deltas
            else "No gbdt run beside them yet."
        )
        lines += [
            f"### {pr}",
            "",
            f"{len(rows)} placements, {len(c)} runs: corr(C, C0) mean {c.mean():.3f}, min "
            f"{c.min():.3f}; sign wrong (≤ 0) in {(c <= 0).sum()}; below 0.9 in "
            f"{(c < 0.9).sum()}. {versus}",
            "",
            "| placement | runs | corr(C, C0) | gbdt val loc | gbdt held-out loc | recipe val loc "
            "| recipe held-out loc | held-out loc minus gbdt (points) |",
            "|---|---|---|---|---|---|---|---|",
            *rows,
            "",
        ]
    return lines or ["(no archived grid runs: `bash studies/coupling_sign/run.sh grid archive`)"]


GRID_HEADER = (
    "# Ten placements, both profiles (issue 69)\n\n"
    "Made by `bash studies/coupling_sign/run.sh grid archive grid_table` from the committed run "
    "records (`results/runs`): the unknown-placement recipe (`model.anomaly_scores=energy "
    "model.coupling_fit=motion model.anomaly_joint_scores=true`, harness graph, W = 32) and "
    "`gbdt` on the same split, one thread per run. corr(C, C0) is the run's coupling against "
    "the true placement; validation figures are the best epoch's, held-out the standard "
    "held-out session's."
)

HEADER = (
    "Made by `bash studies/coupling_sign/run.sh fits default placements joint summary` (W = 32, "
    "energy scores, 20 epochs, one thread per run, two runs side by side; the parts `weights` "
    "and `pose` add rows below when run). `losses`: "
    "the coupling every loss trains (the committed thesis rerun, same recipe); `motion`: set "
    "before training by the motion fit on the training data's healthy running, then frozen; "
    "`+ joint scores`: with `model.anomaly_joint_scores=true` (a score from each joint's own "
    "embedding beside the scattered ones)."
)


EPOCHS_HEADER = (
    "# Retrofit on C0, trained longer (issue 69)\n\n"
    "Made by `bash studies/coupling_sign/run.sh epochs given known coupled archive` (the "
    '`epochs` part at `FORMS="motion motion_joint"`, then `FORMS=motion_joint_coupled` at '
    "`EPOCHS=40` and `20`), then "
    "`python studies/coupling_sign/summarise.py --epochs FILE`, from the committed run records "
    "(`results/runs/default`). C0, retrofit sensing, W = 32, energy scores, the motion-fitted C "
    "frozen; seeds 42-44; 40-epoch runs with patience 8 (20-epoch ones: 6, the coupled 8). "
    "Validation figures are the best epoch's (what selection saw). `given`: the chosen form "
    "told the true placement, frozen (the same four sensors, C known). The known-placement rows "
    "are the structural graph (six packages, each on its joint), the ceiling the issue measures "
    "against; its 20-epoch rows are the thesis rerun's (seed 42)."
)
EPOCH_ROWS = (  # (row name, run folder under results/runs/default/retrofit/C0)
    ("motion + joint scores, 20 epochs", "anomaly_residual_motion_joint"),
    ("motion, 40 epochs", "anomaly_residual_motion_e40"),
    ("motion + joint scores, 40 epochs", "anomaly_residual_motion_joint_e40"),
    ("motion + joint scores + coupled edges, 20 ep.", "anomaly_residual_motion_joint_coupled_e20"),
    ("motion + joint scores + coupled edges, 40 ep.", "anomaly_residual_motion_joint_coupled_e40"),
    (
        "told the true C (`given`) + joint scores + coupled edges, 40 ep.",
        "anomaly_residual_given_joint_coupled_e40",
    ),
)


def epochs_section(archive: Path) -> list[str]:
    """The C0 retrofit forms and training lengths beside ``gbdt`` and the known placement (the
    thesis rerun's 20-epoch rows: seed 42 alone)."""
    c0 = archive / "default" / "retrofit" / "C0"
    structural = THESIS.parent / "structural"
    rows = [("gbdt (harness)", runs_of("retrofit/C0/gbdt/w32/seed*", THESIS))]
    rows += [(name, runs_of(f"{folder}/seed*", c0)) for name, folder in EPOCH_ROWS]
    rows += [
        ("known placement: gbdt (structural)", runs_of("retrofit/C0/gbdt/w32/seed*", structural)),
        ("known placement (structural), 20 epochs",
         runs_of("retrofit/C0/anomaly_residual/w32/seed*", structural)),
        ("known placement (structural), 40 epochs",
         runs_of("known_anomaly_residual_e40/seed*", c0)),
    ]  # fmt: skip
    return table(rows)


CHOSEN = "anomaly_residual_motion_joint_coupled_e40"


def chosen_elsewhere(archive: Path) -> list[str]:
    """The chosen form on the full profile: C0 (three seeds) and two sparse placements (seed
    42), beside the 20-epoch recipe without coupled edges and ``gbdt``."""
    c0 = archive / "default" / "full" / "C0"
    rows = [
        ("C0 gbdt", runs_of("full/C0/gbdt/w32/seed*", THESIS)),
        ("C0 motion + joint scores, 20 epochs", runs_of(f"{RECIPE}/seed*", c0)),
        ("C0 + coupled edges, 40 epochs", runs_of(f"{CHOSEN}/seed*", c0)),
    ]
    for place in ("seed1_m3", "seed2_m4"):
        where = archive / "full" / place
        rows += [
            (f"{place} gbdt", runs_of("gbdt/seed42", where)),
            (f"{place} motion + joint scores, 20 epochs", runs_of(f"{RECIPE}/seed42", where)),
            (f"{place} + coupled edges, 40 epochs", runs_of(f"{CHOSEN}/seed42", where)),
        ]
    return table(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path("outputs/coupling_sign"))
    parser.add_argument("--out", type=Path, default=FITS.with_name("results.md"))
    parser.add_argument(
        "--grid", type=Path, metavar="FILE",
        help="instead: write the ten-placement grid's table from the committed run archive",
    )  # fmt: skip
    parser.add_argument(
        "--epochs", type=Path, metavar="FILE",
        help="instead: write the C0 retrofit training-length table from the committed archive",
    )  # fmt: skip
    args = parser.parse_args()
    if args.epochs:
        lines = [EPOCHS_HEADER, "", *epochs_section(ARCHIVE), "", "## The chosen form on the "
                 "full profile", "", *chosen_elsewhere(ARCHIVE)]  # fmt: skip
        atomic_write_text(args.epochs, "\n".join(lines))
        print(f"wrote {args.epochs}")
        return
    if args.grid:
        atomic_write_text(args.grid, "\n".join([GRID_HEADER, "", *grid_section(ARCHIVE)]))
        print(f"wrote {args.grid}")
        return

    def ours(pattern: str) -> list[dict]:
        return runs_of(pattern, args.root)

    def thesis(pattern: str) -> list[dict]:
        return runs_of(pattern, THESIS)

    lines = ["# The sign-pinned coupling (issue 69)", "", HEADER, ""]
    lines += ["## Placements without training", "", *fits_section(), ""]
    for pr in ("full", "retrofit"):
        lines += [f"## Default placement C0, {pr} profile, seeds 42–44", ""]
        lines += table([
            ("gbdt", thesis(f"{pr}/C0/gbdt/w32/seed*")),
            ("anomaly_residual, losses", thesis(f"{pr}/C0/anomaly_residual/w32/seed*")),
            ("anomaly_residual, motion", ours(f"default/{pr}/C0/anomaly_residual_motion/seed*")),
            ("anomaly_residual, motion + joint scores",
             ours(f"default/{pr}/C0/anomaly_residual_motion_joint/seed*")),
            ("pose_anomaly, losses", thesis(f"{pr}/C0/pose_anomaly/w32/seed*")),
            ("pose_anomaly, motion", ours(f"default/{pr}/C0/pose_anomaly_motion/seed*")),
        ])  # fmt: skip
        lines.append("")
    lines += ["## Drawn placements, seed 42", ""]
    for pr in ("full", "retrofit"):
        rows = []
        for place in sorted(p.name for p in (args.root / "placements" / pr).glob("seed*")):
            rows += [
                (f"{place} gbdt", thesis(f"{pr}/{place}/gbdt/w32/seed42")),
                (f"{place} losses", thesis(f"{pr}/{place}/anomaly_residual/w32/seed42")),
                (f"{place} motion", ours(f"placements/{pr}/{place}/*_motion/seed42")),
                (f"{place} motion + joint scores", ours(f"placements/{pr}/{place}/*_joint/seed42")),
            ]  # fmt: skip
        lines += [f"### {pr}", "", *table(rows), ""]
    lines += ["## Reconstruction weight (C0, full, seed 42)", ""]
    weights = [
        ("0.1 losses", thesis("full/C0/anomaly_residual/w32/seed42")),
        ("0.1 motion", ours("default/full/C0/anomaly_residual_motion/seed42")),
    ]
    for w in ("0.3", "1.0"):
        for fit in ("losses", "motion"):
            runs = ours(f"weights/full/C0/anomaly_residual_{fit}_w{w}/seed42")
            weights.append((f"{w} {fit}", runs))
    lines += [*table(weights), ""]
    atomic_write_text(args.out, "\n".join(lines))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
