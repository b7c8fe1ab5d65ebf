"""The sim-to-real tables from ``experiments/real_arms/campaign.py``'s verdicts.

    python experiments/real_arms/summarise.py > results/real_arms/sim_to_real.md

Networks were replayed through the monitor (alarms, share of ticks called faulty); gbdt, which
has no streaming form, by its window decisions (share of windows called faulty).
"""

from __future__ import annotations

import json
from pathlib import Path

from robohealth_mj.logs.convert import convert_log

VERDICTS = Path("outputs/real_arms/verdicts")
TICK_HZ = 20.0


def _rows(variant: str, kind: str) -> list[dict]:
    out = []
    for path in sorted((VERDICTS / variant / kind).glob("*.json")):
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


def main() -> None:
    variants = sorted(p.name for p in VERDICTS.iterdir() if p.is_dir())
    print("## Healthy real running (after commissioning on the joint-wise logs, 6.8 min)\n")
    print("| model | logs | healthy minutes | alarms | alarms / h | share called faulty |")
    print("|---|---|---|---|---|---|")
    for v in variants:
        rows = _rows(v, "healthy")
        if not rows:
            continue
        secs = sum(r["seconds"] for r in rows)
        n = sum(r["n"] for r in rows)
        faulty = sum(r["faulty"] * r["n"] for r in rows) / max(n, 1)
        alarms = None if rows[0]["alarms"] is None else sum(r["alarms"] for r in rows)
        rate = "n/a (no streaming form)" if alarms is None else f"{alarms / (secs / 3600):.0f}"
        print(
            f"| **{v}** | {len(rows)} | {secs / 60:.1f} | {alarms if alarms is not None else 'n/a'}"
            f" | {rate} | {faulty:.3f} |"
        )
    for kind, title in (
        ("push", "Pushed while holding a pose"),
        ("load", "Runs with an added load"),
    ):
        print(f"\n## {title}\n")
        print("| model | log | seconds | alarms | share called faulty |")
        print("|---|---|---|---|---|")
        for v in variants:
            for r in _rows(v, kind):
                alarms = "n/a" if r["alarms"] is None else r["alarms"]
                print(f"| {v} | {r['log']} | {r['seconds']:.1f} | {alarms} | {r['faulty']:.3f} |")
    print(
        "\nPer log: `outputs/real_arms/verdicts/<model>/<kind>/<log>.json`; "
        "command: `bash results/real_arms/command.sh`."
    )


if __name__ == "__main__":
    main()
