"""The sim-to-real tables from ``studies/real_arms/campaign.py``'s verdicts.

    python studies/real_arms/summarise.py [--runs GLOB,...] [--intervals] > TABLE.md

``--runs``: only the runs (``outputs/real_arms/<run>/``) whose names match one of these globs.
``--intervals``: instead, how sure each monitored share is: a 95 % interval with the logs
resampled (the calls of a log are not independent ticks: most come in a few logs).

Networks were replayed through the monitor (alarms, share of ticks called faulty); gbdt, which
has no streaming form, by its window decisions (share of windows called faulty).
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Iterator
from fnmatch import fnmatch
from pathlib import Path

import numpy as np

from robohealth_mj.logs.convert import convert_log

MOTIONS = {"ptp": "point-to-point", "ur-20_01_17-p": "holding a pose"}  # by the logs' names


KINDS = ("holding a pose", "excitation / free motion", "point-to-point")


def kind_of(log: str) -> str:
    return next((v for k, v in MOTIONS.items() if k in log), "excitation / free motion")


ROOT = Path("outputs/real_arms")
TICK_HZ = 20.0
RESAMPLES = 10_000  # of the logs, for the intervals


def _rows(verdicts: Path, variant: str, kind: str) -> list[dict]:
    out = []
    for path in sorted((verdicts / variant / kind).glob("*.json")):
        d = json.loads(path.read_text())
        if "metrics" in d:  # evaluate: windows, all labelled healthy
            m = d["metrics"]
            n = m["windows"]
            seconds = sum(len(x.t) for f in d["data"] for x in convert_log(f)[1]) / TICK_HZ
            out.append({"log": path.stem, "seconds": seconds, "alarms": None,
                        "faulty": 1.0 - m["accuracy"], "n": n})  # fmt: skip
        else:  # monitor replay
            out.append({"log": path.stem, "seconds": d["ticks"] / TICK_HZ,
                        "alarms": d["false_alarms"], "faulty": d["false_positive_rate"],
                        "n": d["decided_ticks"]})  # fmt: skip
    return out


def _faulty(rows: list[dict]) -> float:
    """The share of the rows' decided ticks (windows for gbdt) called faulty."""
    return sum(r["faulty"] * r["n"] for r in rows) / max(sum(r["n"] for r in rows), 1)


def ablation(runs: list[tuple[str, Path]]) -> None:
    """One row per run and model: the simulated validation (at the best epoch), the program logs
    (selection) and the monitored logs by motion, alarms per hour and training time."""
    print("## Ablation: what the model is trained on\n")
    print("| run | model | validation acc. / loc. (sim) | program logs (selection) | monitored: "
          "all | holds | excitation | point-to-point | alarms / h | train s |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|")
    for run, verdicts in runs:
        models = ROOT / verdicts.parent.name / "models"
        for v in sorted(p.name for p in verdicts.iterdir() if p.is_dir()):
            rows = _rows(verdicts, v, "healthy")
            (summary,) = models.rglob(f"{v}/w32/seed*/train_summary.json")
            d = json.loads(summary.read_text())
            best = next(h for h in d["history"] if h["epoch"] == d["best_epoch"])
            program = _rows(verdicts, v, "program")
            kinds = [_faulty([r for r in rows if kind_of(r["log"]) == k]) for k in KINDS]
            alarms = None if rows[0]["alarms"] is None else sum(r["alarms"] for r in rows)
            hours = sum(r["seconds"] for r in rows) / 3600
            name = f"**{v}**" if v == "gbdt" else v
            print(f"| {run} | {name} | {best['val_accuracy']:.3f} / "
                  f"{best['val_localisation']:.3f} | "
                  f"{f'{_faulty(program):.3f}' if program else 'not run'} | {_faulty(rows):.3f} | "
                  + " | ".join(f"{k:.3f}" for k in kinds)
                  + f" | {'n/a' if alarms is None else f'{alarms / hours:.0f}'} | "
                  f"{d['wall_seconds']:.0f} |")  # fmt: skip
    print()


def _line(run: str, v: str, what: str, rows: list[dict]) -> str:
    secs = sum(r["seconds"] for r in rows)
    faulty = _faulty(rows)
    alarms = None if rows[0]["alarms"] is None else sum(r["alarms"] for r in rows)
    rate = "n/a (no streaming form)" if alarms is None else f"{alarms / (secs / 3600):.0f}"
    name = f"**{v}**" if v == "gbdt" else v
    return (f"| {run} | {name} | {what} | {len(rows)} | {secs / 60:.1f} | "
            f"{alarms if alarms is not None else 'n/a'} | {rate} | {faulty:.3f} |")  # fmt: skip


def _monitored(runs: list[tuple[str, Path]]) -> Iterator[tuple[str, str, Path, list[dict]]]:
    """``(run, model, verdicts, rows)`` for each run's models with monitored healthy logs."""
    for run, verdicts in runs:
        for v in sorted(p.name for p in verdicts.iterdir() if p.is_dir()):
            rows = _rows(verdicts, v, "healthy")
            if rows:
                yield run, v, verdicts, rows


def intervals(runs: list[tuple[str, Path]], seed: int = 0) -> None:
    """Per run and model: the monitored share called faulty, how many logs hold its calls, and
    its 95 % interval with the logs resampled with replacement (percentiles)."""
    rng = np.random.default_rng(seed)
    print("## How sure the monitored share called faulty is\n")
    print(f"The monitored healthy logs resampled with replacement ({RESAMPLES:,} times, seed "
          f"{seed}); the interval is the 2.5th to 97.5th percentile of the share.\n")  # fmt: skip
    print("Last column: the share over the program logs (selection) and the monitored ones "
          "together, every healthy log that neither commissions nor trains.\n")  # fmt: skip
    print("| run | model | logs | ticks called faulty / decided | share | logs with a call "
          "| 95 % interval | with the program logs |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for run, v, verdicts, rows in _monitored(runs):
        called = np.array([round(r["faulty"] * r["n"]) for r in rows], float)
        decided = np.array([r["n"] for r in rows], float)
        draws = rng.integers(len(rows), size=(RESAMPLES, len(rows)))
        shares = called[draws].sum(axis=1) / np.maximum(decided[draws].sum(axis=1), 1)
        low, high = np.percentile(shares, [2.5, 97.5])
        program = _rows(verdicts, v, "program")
        pooled = f"{_faulty(rows + program):.4f}" if program else "not run"
        print(f"| {run} | {v} | {len(rows)} | {called.sum():.0f} / {decided.sum():.0f} | "
              f"{called.sum() / decided.sum():.4f} | {(called > 0).sum()} | "
              f"{low:.4f}-{high:.4f} | {pooled} |")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="*", help="comma-separated globs of run names")
    parser.add_argument(
        "--intervals", action="store_true", help="only the shares' intervals, logs resampled"
    )
    args = parser.parse_args()
    globs = args.runs.split(",")
    # campaign.py --name, and _program / _rate<R> where commissioned otherwise (--commission,
    # --healthy-rate), _motion where monitored with --observability motion
    runs = [(p.parent.name + p.name.removeprefix("verdicts"), p)
            for p in sorted(ROOT.glob("*/verdicts*"))
            if any(fnmatch(p.parent.name, g) for g in globs)]  # fmt: skip
    if args.intervals:
        intervals(runs)
        return
    ablation(runs)
    print("## Healthy real running (after commissioning on the joint-wise logs, 6.8 min)\n")
    print("`program (selection)`: the twelve program logs (5.6 min), which no run is judged on "
          "(in-sample for the runs that replay them: replay, mixed). The rest: the monitored "
          "healthy logs without payload that neither commission nor are replayed "
          "(`healthy_monitored` in campaign.py). Run suffixes: `_program` commissioned on the "
          "program logs as well, `_rate<R>` at healthy rate R, `_motion` monitored with "
          "`observability=motion`.\n")  # fmt: skip
    print("| run | model | logs | n | healthy minutes | alarms | alarms / h "
          "| share called faulty |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for run, v, verdicts, rows in _monitored(runs):
        program = _rows(verdicts, v, "program")
        if program:
            print(_line(run, v, "program (selection)", program))
        print(_line(run, v, "all monitored", rows))
        for kind in sorted({kind_of(r["log"]) for r in rows}):
            print(_line(run, v, kind, [r for r in rows if kind_of(r["log"]) == kind]))
    for kind, title in (
        ("push", "Pushed while holding a pose"),
        ("load", "Runs with an added load"),
    ):
        print(f"\n## {title}\n")
        print("| run | model | log | seconds | alarms | share called faulty |")
        print("|---|---|---|---|---|---|")
        for run, verdicts in runs:
            for v in sorted(p.name for p in verdicts.iterdir() if p.is_dir()):
                for r in _rows(verdicts, v, kind):
                    alarms = "n/a" if r["alarms"] is None else r["alarms"]
                    print(f"| {run} | {v} | {r['log']} | {r['seconds']:.1f} | {alarms} | "
                          f"{r['faulty']:.3f} |")  # fmt: skip
    print(
        "\nPer log: `outputs/real_arms/<run>/verdicts/<model>/<kind>/<log>.json`; "
        "command: `bash studies/real_arms/run.sh` (the step that writes this file)."
    )


if __name__ == "__main__":
    main()
