"""``bench mixed``: a mixed fleet's cost per stream against each arm's own fleet, in one run.

Two models (say a UR5e's six-joint and an FR3's seven-joint), each with its recordings: each
arm's fleet alone at ``streams`` streams, then both in one process (``streams`` of each, one
:class:`~robohealth_mj.runtime.mixed.MixedFleet`), in alternated rounds so outside load falls on
all three alike. Reported: the step's thread time per stream per tick, the second arm's cost per
stream over the first's beside the ratio of their node counts (the cost a graph of more nodes
should carry), and the mixed fleet's cost per stream against the mean of the two alone.
"""

from __future__ import annotations

import gc
import time

import numpy as np

from robohealth_mj.benchmarks.streams import TICK_S, Replay
from robohealth_mj.data.arrays import expand_paths, load_recordings
from robohealth_mj.data.relative import to_raw
from robohealth_mj.runtime.fleet import freeze_startup_heap
from robohealth_mj.runtime.mixed import MixedFleet, Rows


def _replay(data: str, streams: int, seed: int) -> tuple[Replay, int]:
    rec = load_recordings(expand_paths(data))
    return Replay.of(to_raw(rec.x, rec.arms[0]), streams, seed), rec.graph.n_nodes


def _timed(fleet: MixedFleet, replays: dict[str, Replay], ticks: int, warm: int) -> float:
    """Median step time per tick (s) of ``fleet`` over ``ticks`` ticks after ``warm``."""
    slots = {
        name: fleet.register(name, [f"{name}{k:05d}" for k in range(len(r.offsets))])
        for name, r in replays.items()
    }
    times = []
    for k in range(warm + ticks):
        rows = {}
        for name, replay in replays.items():
            index, t, x = replay.tick(k)
            rows[name] = Rows(slots[name], index, t, x)
        start = time.perf_counter()
        fleet.step(rows)
        if k >= warm:
            times.append(time.perf_counter() - start)
    return float(np.median(times))


def bench_mixed(models: list[str], data: list[str], streams: int, ticks: int, rounds: int):
    """Each arm's fleet alone and both together, ``rounds`` times alternated; prints a table."""
    names = [f"arm{k}" for k in range(len(models))]
    replays, nodes = {}, {}
    for k, (name, d) in enumerate(zip(names, data, strict=True)):
        replays[name], nodes[name] = _replay(d, streams, k)
    configs = {name: [name] for name in names} | {"mixed": names}
    runs: dict[str, list[float]] = {key: [] for key in configs}
    freeze_startup_heap()
    for _ in range(rounds):
        for key, members in configs.items():
            fleet = MixedFleet({m: models[names.index(m)] for m in members}, threads=1,
                               shards=2, capacity=streams, max_streams=streams)  # fmt: skip
            warm = max(f.window for f in fleet.members.values()) + 2
            runs[key].append(_timed(fleet, {m: replays[m] for m in members}, ticks, warm))
            fleet.close()
            del fleet
            gc.collect()
    per_stream = {k: float(np.median(v)) / (streams * len(configs[k])) for k, v in runs.items()}
    print(f"{streams} streams per arm kind; median step time over {ticks} ticks, {rounds} "
          f"alternated rounds; tick budget {TICK_S * 1e3:.0f} ms\n"
          "| fleet | streams | nodes per arm | step ms (median of rounds) | us per stream |\n"
          "|---|---|---|---|---|")  # fmt: skip
    for key, members in configs.items():
        shown = "+".join(str(nodes[m]) for m in members)
        print(f"| {key} | {streams * len(members)} | {shown} | "
              f"{np.median(runs[key]) * 1e3:.2f} | {per_stream[key] * 1e6:.1f} |")  # fmt: skip
    first, second = names[0], names[-1]
    cost = per_stream[second] / per_stream[first]
    node_ratio = nodes[second] / nodes[first]
    alone = np.mean([per_stream[n] for n in names])
    print(f"cost per stream {second}/{first}: {cost:.3f} against the node ratio {node_ratio:.3f} "
          f"({cost / node_ratio - 1:+.1%}); mixed fleet per stream / mean of the fleets alone: "
          f"{per_stream['mixed'] / alone:.3f}")  # fmt: skip
    return {"per_stream_s": per_stream, "cost_ratio": cost, "node_ratio": node_ratio,
            "mixed_over_alone": per_stream["mixed"] / alone}  # fmt: skip
