"""``python -m robohealth_mj.tune_alarms --model M --data SESSION``: choose alarm settings on a
selection recording (record one with a seed of its own; never tune on the held-out session).

The model's decisions are computed once (``--healthy``: also on a healthy-only session, so that
false alarms per hour rest on hours, not minutes), then every policy of the grid replays over
them; the
table (markdown) lists each policy's detection rate, false alarms and latency, and the last line
names the chosen policy (see :func:`~robohealth_mj.deploy.alarm_sweep.choose`). Put it in
``conf/monitor.yaml``'s ``evidence`` and ``alarm`` blocks. The grid covers memory (``evidence``:
how window probabilities accumulate) and the alarm's debouncing together, since each changes
what the other should be.
"""

from __future__ import annotations

import argparse

from robohealth_mj.common.config import compose_config
from robohealth_mj.common.errors import one_line_errors
from robohealth_mj.runtime.monitor import decide_every

with one_line_errors("tune_alarms"):  # a missing extra is one line, not a traceback
    from robohealth_mj.deploy.alarm_sweep import choose, meets_targets, replay_decisions, sweep


def _f(value: float | None) -> str:
    return "–" if value is None else f"{value:.3g}"


def _moot(row: dict, key: str) -> str:
    """An evidence setting, or '–' where it does nothing (no memory)."""
    return f"{row[key]:g}" if row["horizon_s"] > 0 else "–"


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.tune_alarms", description=__doc__
    )
    parser.add_argument("--model", required=True, help="an exported model.onnx")
    parser.add_argument("--data", required=True, help="a selection session's graphs.jsonl")
    parser.add_argument("--healthy", help="a healthy-only selection session, for false alarms/h")
    parser.add_argument(
        "--decide-every", type=int, default=None,
        help="the model every this many ticks, as the monitor runs it (default: the monitor's "
        "decide_every)",
    )  # fmt: skip
    args = parser.parse_args(argv)
    with one_line_errors("tune_alarms"):
        every = decide_every(
            compose_config("monitor", []).decide_every
            if args.decide_every is None
            else args.decide_every
        )
        decisions = replay_decisions(args.model, args.data, every)
        healthy = replay_decisions(args.model, args.healthy, every) if args.healthy else None
    rows = sweep(decisions, healthy=healthy)
    print(
        f"selection: {args.data} (faults)"
        + (f" + {args.healthy} (healthy)" if args.healthy else "")
        + f"; {rows[0]['healthy_hours']:.2f} h of settled healthy running\n"
    )
    print(
        "| horizon_s | clip | floor | raise_after | clear_after | min_confidence | detected | "
        "observable detected | right at rise | false alarm ticks | false alarms / h | "
        "to class s | to joint s | meets targets |\n|---|---|---|---|---|---|---|---|---|---|---|"
        "---|---|---|"
    )
    for r in rows:
        print(
            f"| {r['horizon_s']:g} | {_moot(r, 'clip')} | {_moot(r, 'floor')} | "
            f"{r['raise_after']} | "
            f"{r['clear_after']} | {r['min_confidence']} | {_f(r['detection_rate'])} | "
            f"{_f(r['observable_detection_rate'])} | "
            f"{_f(r['right_at_rise_rate'])} | {_f(r['false_alarm_rate'])} | "
            f"{_f(r['false_alarms_per_hour'])} | {_f(r['class_latency_s_median'])} | "
            f"{_f(r['joint_latency_s_median'])} | {'yes' if meets_targets(r) else ''} |"
        )
    best = choose(rows)
    memory = (
        f" evidence.clip={best['clip']:g} evidence.floor={best['floor']:g}"
        if best["horizon_s"] > 0
        else ""
    )
    print(
        f"\nchosen: evidence.horizon_s={best['horizon_s']:g}{memory} "
        f"alarm.raise_after={best['raise_after']} "
        f"alarm.clear_after={best['clear_after']} alarm.min_confidence={best['min_confidence']} "
        f"({'meets every target' if meets_targets(best) else 'meets no policy every target'}; "
        f"selection data: {args.data})"
    )
    return best
