"""Tables of the planner's figures (issue 68) from the lives campaign's runs.

    python studies/wear/planner_tables.py outputs/lives/planner_s42/lives.json [...] > planner.md

One run per seed. The ablation: every index model's figures on the validation lives (where the
index model and the warning are chosen), the held-out lives and the fresh lives, averaged over the
seeds; then the chosen model per seed against the targets; each life's first warning; and the
wearing joint's index error by mode and joint (where the physics caps it).
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from robohealth_mj.reporting.markdown import heading

GROUPS = ("validation", "held_out", "fresh")


def _tune(w: dict) -> str:
    """A tuned warning: lead days, floor, the trend's fit (the last sessions or since the floor
    was reached) and the fewest sessions it is drawn through."""
    return (
        f"{w['lead_days']:g}, {w['floor']:g}, {w.get('fit', 'window')} ≥ {w.get('min_sessions', 3)}"
    )


def _share_in_band(outcomes: list[str]) -> str:
    hits = sum(o == "in_band" for o in outcomes)
    return f"{hits / len(outcomes):.2f} ({hits}/{len(outcomes)})"


def _fmt(values: list[float], digits: int = 3) -> str:
    if len(values) == 1:
        return f"{values[0]:.{digits}f}"
    return f"{np.mean(values):.{digits}f} ± {np.std(values):.{digits}f}"


def ablation(runs: list[dict]) -> list[str]:
    head = ["index model", "chosen on seeds", "lead, floor, fit ≥ sessions (per seed)"]
    for g in GROUPS:
        head += [f"{g}: wearing-joint MAE", f"{g}: in band", f"{g}: early / late / wrong / missed",
                 f"{g}: warnings / 100 healthy d"]  # fmt: skip
    lines = heading("Index models (mean ± sd over seeds; chosen on the validation lives)", head)
    names = [r["index_model"] for r in runs[0]["index_models"]]
    for name in names:
        rows = [next(r for r in run["index_models"] if r["index_model"] == name) for run in runs]
        chosen = [str(run["seed"]) for run in runs if run["chosen"] == name]
        tune = "; ".join(_tune(r["warning"]) for r in rows)
        cells = [f"**{name}**" if chosen else name, ", ".join(chosen) or "—", tune]
        for g in GROUPS:
            w = [r["groups"][g]["warnings"] for r in rows]
            cells += [
                _fmt([r["groups"][g]["index"]["wearing_joint_mae"] for r in rows]),
                _fmt([x["in_band"] for x in w], 2),
                " / ".join(
                    f"{np.mean([x[o] for x in w]):.2f}"
                    for o in ("early", "late", "wrong_joint", "missed")
                ),
                _fmt([x["warnings_per_100_healthy_days"] for x in w], 2),
            ]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def targets(runs: list[dict]) -> list[str]:
    head = ["seed", "index model", "lead, floor, fit ≥ sessions", "at grid edge"]
    for g in ("held_out", "fresh"):
        head += [f"{g}: wearing-joint MAE (≤ 0.05)", f"{g}: other joints read (mean, p95)",
                 f"{g}: in band (≥ 0.90)", f"{g}: warnings / 100 healthy d (≤ 1)"]  # fmt: skip
    lines = heading("The chosen index model against the targets", head)
    for run in runs:
        row = next(r for r in run["index_models"] if r["index_model"] == run["chosen"])
        w = row["warning"]
        cells = [str(run["seed"]), run["chosen"], _tune(w), "yes" if w["at_edge"] else "no"]
        for g in ("held_out", "fresh"):
            i, x = row["groups"][g]["index"], row["groups"][g]["warnings"]
            cells += [
                f"{i['wearing_joint_mae']:.3f}",
                f"{i['other_joints_mean_reading']:.3f}, {i['other_joints_p95_reading']:.3f}",
                f"{x['in_band']:.2f} ({round(x['in_band'] * x['lives'])}/{x['lives']})",
                f"{x['warnings_per_100_healthy_days']:.2f} ({x['warned_healthy_days']}/"
                f"{x['healthy_arm_days']} d)",
            ]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def _step(name: str) -> int:
    """The ablation's steps in the order they were added (JSON keeps its keys sorted)."""
    first = ("last sessions", "+ since the floor")
    return first.index(name) if name in first else len(first)


def fit_ablation(runs: list[dict]) -> list[str]:
    """The chosen index model's warning tuned on the validation lives with the trend through
    the last sessions only, then also since the index reached the floor, then also through at
    least five sessions (the campaign's ``ablation``)."""
    head = ["seed", "warning tuned over", "lead, floor, fit ≥ sessions"]
    for g in GROUPS:
        head += [f"{g}: in band", f"{g}: early / late / wrong / missed"]
    head.append("held_out: warnings / 100 healthy d")
    lines = heading("The warning's trend (chosen index model; tuned on the validation lives)", head)
    for run in runs:
        row = next(r for r in run["index_models"] if r["index_model"] == run["chosen"])
        steps = sorted(row.get("ablation", {}).items(), key=lambda kv: _step(kv[0]))
        for name, option in steps:
            cells = [str(run["seed"]), name, _tune(option["warning"])]
            for g in GROUPS:
                x = option["warnings"][g]
                cells += [f"{x['in_band']:.2f} ({round(x['in_band'] * x['lives'])}/{x['lives']})",
                          " / ".join(f"{x[o]:.2f}" for o in ("early", "late", "wrong_joint",
                                                            "missed"))]  # fmt: skip
            cells.append(f"{option['warnings']['held_out']['warnings_per_100_healthy_days']:.2f}")
            lines.append("| " + " | ".join(cells) + " |")
    return lines


def per_life(runs: list[dict]) -> list[str]:
    head = ["group", "life", "mode", "joint", "path", "failure day"]
    head += [f"seed {run['seed']}: outcome (lead days)" for run in runs]
    lines = heading("First warning per wearing life (chosen index model)", head)
    chosen = [next(r for r in run["index_models"] if r["index_model"] == run["chosen"])
              for run in runs]  # fmt: skip
    for g in ("held_out", "fresh"):
        for k, life in enumerate(chosen[0]["groups"][g]["warnings"]["per_life"]):
            cells = [g, life["life"], life["mode"], life["joint"], life["path"],
                     f"{life['failure_day']:g}"]  # fmt: skip
            for row in chosen:
                x = row["groups"][g]["warnings"]["per_life"][k]
                lead = "" if x["lead_days"] is None else f" ({x['lead_days']:g})"
                cells.append(x["outcome"] + lead)
            lines.append("| " + " | ".join(cells) + " |")
    return lines


def strata(runs: list[dict]) -> list[str]:
    """Wearing-joint MAE by mode and joint over the held-out and fresh lives and seeds."""
    cell: dict[tuple, list[float]] = defaultdict(list)
    for run in runs:
        row = next(r for r in run["index_models"] if r["index_model"] == run["chosen"])
        for g in ("held_out", "fresh"):
            for life in row["groups"][g]["index"]["per_life"]:
                cell[(life["mode"], life["joint"])].append(life["mae"])
    head = ["mode", "joint", "lives × seeds", "wearing-joint MAE"]
    lines = heading("Wearing-joint index error by mode and joint (held-out + fresh lives)", head)
    for (mode, joint), v in sorted(cell.items(), key=lambda kv: -np.mean(kv[1])):
        lines.append(f"| {mode} | {joint} | {len(v)} | {np.mean(v):.3f} |")
    return lines


def observable(runs: list[dict], unobservable: list[tuple[str, str]]) -> list[str]:
    """The chosen index's wearing-joint MAE (every day of every life weighs the same) with and
    without the lives of the (mode, joint) pairs no channel can read (argued from the channels'
    response in ``severity_channels.md``)."""
    head = ["seed", "group", "wearing-joint MAE", "in band", "lives left out",
            "MAE without them", "in band without them"]  # fmt: skip
    pairs = ", ".join(f"{m} at {j}" for m, j in unobservable) or "none"
    lines = heading(
        f"The planner's figures on what the channels can read (left out: {pairs})", head
    )
    for run in runs:
        for g in ("held_out", "fresh"):
            rows = [r for r in run["rul"] if r["group"] == g and r["estimator"] == "trend"]
            keep = [r for r in rows if (r["mode"], r["joint"]) not in unobservable]
            err = lambda rs: np.abs(np.concatenate([np.subtract(r["index"], r["truth"])  # noqa: E731
                                                    for r in rs])).mean()  # fmt: skip
            band = lambda rs: _share_in_band([r["first_warning_outcome"] for r in rs])  # noqa: E731
            cells = [str(run["seed"]), g, f"{err(rows):.3f}", band(rows),
                     str(len(rows) - len(keep)), f"{err(keep):.3f}" if keep else "—",
                     band(keep) if keep else "—"]  # fmt: skip
            lines.append("| " + " | ".join(cells) + " |")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument(
        "--unobservable",
        default="",
        help="mode:joint pairs no channel can read, comma-separated (struct_weaken:shoulder_pan)",
    )
    args = ap.parse_args()
    unobservable = [tuple(pair.split(":", 1)) for pair in args.unobservable.split(",") if pair]
    runs = [json.loads(p.read_text()) for p in args.runs]
    print("\n".join(["# Wear figures a planner can trust (issue 68)", "",
                     f"Runs: {', '.join(str(p) for p in args.runs)}. Band: "
                     f"{runs[0]['band_days'][0]:g}-{runs[0]['band_days'][1]:g} days before "
                     "failure, the first warning on any joint.", "",
                     *targets(runs), "", *observable(runs, unobservable), "",
                     *fit_ablation(runs), "", *ablation(runs), "",
                     *strata(runs), "",
                     *per_life(runs)]))  # fmt: skip


if __name__ == "__main__":
    main()
