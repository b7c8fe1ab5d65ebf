"""Does the physics carry a wearing joint's severity where the health index does not?

    python studies/wear/severity_channels.py outputs/lives/planner_s42 > severity_channels.md

For every wearing life of the held-out and fresh lives, each day's severity on the wearing joint
against (a) the health index the run's chosen index model reads (the daily reading, and the
monitor's monotone reading on the last day) and (b) the day's mean of the one
recorded channel each mechanical mode acts on, on the wearing joint while it turns: friction adds
a torque against the motion (``effort_residual`` x sign(``vel``)); a backlash gap lets the link
lag its target (RMS ``pos_error``); and (c) the four modes' signatures
(:mod:`robohealth_mj.prognostics.signature`): the severity they read with the life's mode named
(monotone, as the monitor reads it), and how often they name that mode themselves (with the
last days' loads, as the monitor calls it) on days worn
past 0.1. Per mode: the rank correlation of (a) and (b) with the severity over
the life's days, and the linear correlation (how nearly a straight line), means over lives; for
the index, the share of the severity range it spans
(the last day's reading over the truth's). A channel that keeps rising where the index levels off
says the window model's severity head, not the physics, caps the index.
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path

import campaign  # this folder's lives campaign: the runs' cached scores and channels
import numpy as np

from robohealth_mj.prognostics.channels import MODES
from robohealth_mj.prognostics.health import MECHANICAL_CLASSES, monotone_index
from robohealth_mj.prognostics.index_model import FittedIndex
from robohealth_mj.prognostics.signature import SPEED
from robohealth_mj.reporting.markdown import heading
from robohealth_mj.schema import JOINT_NAMES

GROUPS = ("heldout_lives", "fresh_lives")


def spearman(a: np.ndarray, b: np.ndarray) -> float:
    """Rank correlation (ties broken by order: the lives' severities rise strictly)."""
    ranks = [np.argsort(np.argsort(v, kind="stable")) for v in (a, b)]
    return float(np.corrcoef(*ranks)[0, 1])


def pearson(a: np.ndarray, b: np.ndarray) -> float:
    """Linear correlation: how nearly a reading is a straight line in the severity."""
    return float(np.corrcoef(a, b)[0, 1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=Path)
    ap.add_argument("--standard", default="outputs/corpus/standard", type=Path)
    args = ap.parse_args()
    every = json.loads((args.run / "health_raw.json").read_text())
    campaign.add_channels(every)
    fits = campaign.channel_fits(args.run, [f"{args.standard}/train_*"], every)
    scales = fits.scales
    scores = {k: v for k, v in every.items() if v["role"] in GROUPS and v["joint"]}
    index = FittedIndex.load(args.run / "calibration.json")
    rows: dict[str, list] = defaultdict(list)
    for life in scores.values():
        j = JOINT_NAMES.index(life["joint"])
        truth = np.array([d["truth"][j] for d in life["days"]])
        daily = np.array([index.calibrate(d)[j] for d in life["days"]])
        seen = index.life(life["days"])[:, j]
        row = {"index_rho": spearman(daily, truth), "index_r": pearson(daily, truth),
               "index_mae": float(np.abs(seen - truth).mean()),
               "index_span": seen[-1] / max(truth[-1], 1e-9)}  # fmt: skip
        if life["mode"] in MODES:
            m = MODES.index(life["mode"])
            readings = np.array([d["channel"][m][j] for d in life["days"]])
            ok = np.isfinite(readings)
            units = np.clip(np.nan_to_num(readings / scales[m, j]), 0.0, 1.0)
            reading = np.array([monotone_index(units[: k + 1])[-1] for k in range(len(units))])
            row |= {"channel_rho": spearman(readings[ok], truth[ok]),
                    "channel_r": pearson(readings[ok], truth[ok]),
                    "channel_mae": float(np.abs(reading - truth).mean())}  # fmt: skip
        if fits.signatures is not None:  # the four modes' signatures: the mode known, and called
            m = MECHANICAL_CLASSES.index(life["mode"])
            named = np.full(len(JOINT_NAMES), m)
            read = np.array([fits.signatures.read(np.asarray(d["channel"]), named)[j]
                             for d in life["days"]])  # fmt: skip
            read = np.nan_to_num(read)
            mono = np.array([monotone_index(read[: k + 1])[-1] for k in range(len(read))])
            called = [fits.signatures.call(np.asarray(d["channel"]), d["recent_channel"])[0][j] == m
                      for d, t in zip(life["days"], truth, strict=True) if t > 0.1]  # fmt: skip
            row |= {"signature_mae": float(np.abs(mono - truth).mean()),
                    "signature_called": float(np.mean(called)) if called else np.nan}  # fmt: skip
        rows[life["mode"]].append(row)
    head = [
        "mode",
        "lives",
        "daily index: rank / linear corr.",
        "monitor's index: MAE; last day / truth",
        "channel: rank / linear corr.",
        "channel in severity units: MAE",
        "signature, mode known: MAE",
        "signature names the mode (worn > 0.1)",
    ]
    chosen = json.loads((args.run / "lives.json").read_text())["chosen"]
    print(f"Run {args.run} ({chosen}); channel scales (reading per unit severity, per joint):")
    for m, mode in enumerate(MODES):
        print(f"{mode} {np.round(scales[m], 4).tolist()}")
    print()
    title = "The wearing joint's severity: the health index against the channel (held-out + fresh)"
    print("\n".join(heading(title, head)))
    mean = lambda v, k: np.mean([r[k] for r in v if k in r])  # noqa: E731
    for mode, v in sorted(rows.items()):
        has = any("channel_r" in r for r in v)
        print(
            f"| {mode} | {len(v)} | {mean(v, 'index_rho'):.2f} / {mean(v, 'index_r'):.2f} | "
            f"{mean(v, 'index_mae'):.3f}; {mean(v, 'index_span'):.2f} | "
            + (
                f"{mean(v, 'channel_rho'):.2f} / {mean(v, 'channel_r'):.2f} | "
                f"{mean(v, 'channel_mae'):.3f} |"
                if has
                else "— | — |"
            )
            + (
                f" {mean(v, 'signature_mae'):.3f} | {mean(v, 'signature_called'):.2f} |"
                if fits.signatures is not None
                else " — | — |"
            )
        )

    if fits.signatures is not None:
        speeds = np.nanmedian([np.asarray(d["channel"], float)[SPEED] for life in scores.values()
                               for d in life["days"]], axis=0)  # fmt: skip
        print()
        title = "How far each mode moves its channels, in healthy day-to-day spreads"
        print("\n".join(heading(title, ["mode", "severity", *JOINT_NAMES])))
        for severity in (0.3, 1.0):
            size = fits.signatures.size(severity, speeds)
            for m, mode in enumerate(MECHANICAL_CLASSES):
                cells = " | ".join(f"{v:.0f}" for v in size[m])
                print(f"| {mode} | {severity:g} | {cells} |")


if __name__ == "__main__":
    main()
