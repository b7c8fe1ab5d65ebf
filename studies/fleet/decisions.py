"""Replay a recording through the fleet runtime and write every decision, to compare runtimes.

    python studies/fleet/decisions.py --model M --data DIR --out decisions.npz

Stream ``k`` replays the recording from its own offset; every 97th tick one stream skips a sample
(a gap: its window and evidence restart) and every 89th tick one stream sends two samples (a
burst). Written per decided row: the tick, the stream, the top class, the top joint, the alarm
state, class and joint, and the class probabilities. The printed digests say whether two
runtimes (two checkouts on ``PYTHONPATH``) decided alike: ``decisions`` covers classes, joints
and alarms; ``probabilities`` the float32 bytes.
"""

from __future__ import annotations

import argparse
import hashlib
from pathlib import Path

import numpy as np

from robohealth_mj.data.arrays import expand_paths, load_recordings
from robohealth_mj.runtime.evidence import EvidencePolicy
from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime


def replay(model: str, x: np.ndarray, streams: int, ticks: int) -> dict[str, np.ndarray]:
    fleet = FleetRuntime(model, capacity=streams, max_streams=streams,
                         evidence=EvidencePolicy(horizon_s=10.0))  # fmt: skip
    slots = fleet.register([f"arm{k:04d}" for k in range(streams)])
    offsets = (np.random.default_rng(0).integers(0, len(x), streams)).astype(np.int64)
    index = np.zeros(streams, np.int64)
    rows: dict[str, list[np.ndarray]] = {k: [] for k in ("tick", "stream", "cls", "joint",
                                                          "alarm", "alarm_class", "alarm_joint",
                                                          "probs")}  # fmt: skip
    for tick in range(ticks):
        send = np.ones(streams, bool)
        if tick % 97 == 96:
            send[tick % streams] = False
            index[tick % streams] += 1  # the skipped sample
        who = np.flatnonzero(send)
        burst = (tick * 7) % streams if tick % 89 == 88 else -1
        if burst >= 0:
            who = np.sort(np.r_[who, burst])  # the burst's second sample follows the first
        first = np.r_[True, who[1:] != who[:-1]]
        i = index[who] + (~first)
        r = fleet.step(slots[who], i, 0.05 * (i + 1), x[(offsets[who] + i) % len(x)])
        index[who] = i + 1
        done = r.status == DECIDED
        decided = {
            "tick": np.full(done.sum(), tick),
            "stream": who[done],
            "cls": r.probs[done].argmax(1),
            "joint": r.joint_scores[done].argmax(1),
            "alarm": r.alarm[done],
            "alarm_class": r.alarm_class[done],
            "alarm_joint": r.alarm_joint[done],
            "probs": r.probs[done],
        }
        for key, value in decided.items():
            rows[key].append(np.asarray(value))
    return {k: np.concatenate(v) for k, v in rows.items()}


def digest(out: dict[str, np.ndarray], keys) -> str:
    h = hashlib.sha256()
    for k in keys:
        h.update(np.ascontiguousarray(out[k].astype(np.int64 if k != "probs" else np.float32)))
    return h.hexdigest()[:16]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", required=True)
    parser.add_argument("--data", nargs="+", required=True)
    parser.add_argument("--streams", type=int, default=300)
    parser.add_argument("--ticks", type=int, default=1200)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    x = load_recordings(expand_paths(args.data)).x
    out = replay(args.model, x, args.streams, args.ticks)
    np.savez_compressed(args.out, **out)
    decisions = ("tick", "stream", "cls", "joint", "alarm", "alarm_class", "alarm_joint")
    print(
        f"{len(out['tick'])} decided rows; decisions {digest(out, decisions)}; "
        f"probabilities {digest(out, ('probs',))}; alarms raised {(out['alarm'] == 1).sum()}"
    )


if __name__ == "__main__":
    main()
