"""``bench streams`` and ``bench soak``: the fleet runtime's load and soak reports."""

from __future__ import annotations

import argparse
import os

import numpy as np

from robohealth_mj.benchmarks.common import onnx_flops, sgemm_rate
from robohealth_mj.benchmarks.soak import soak
from robohealth_mj.benchmarks.streams import TICK_S, search, trial
from robohealth_mj.common.errors import InputError
from robohealth_mj.runtime.evidence import EvidencePolicy
from robohealth_mj.runtime.fleet import FleetRuntime, freeze_startup_heap
from robohealth_mj.runtime.phases import PhaseClock

ONNX_PHASES = ("encode (ONNX)", "head (ONNX)")


def _frames(data: list[str]):
    from robohealth_mj.data.arrays import expand_paths, load_recordings

    return load_recordings(expand_paths(data)).x


def _row(label: str, r: dict) -> str:
    return (
        f"| {label} | {r['streams']} | {r['p50_ms']:.1f} | {r['p99_ms']:.1f} | {r['max_ms']:.1f} "
        f"| {r['late_ticks']} | {r['cpu_share']:.0%} |"
    )


def model_flops(model: str, incremental: bool = True) -> float:
    """FLOPs the fleet step's ONNX calls perform per stream and tick (both incremental graphs,
    or the windowed graph on one window)."""
    import base64

    import onnxruntime as ort

    from robohealth_mj import schema
    from robohealth_mj.runtime.metadata import read_metadata

    meta = read_metadata(model)

    def session(m, options):
        return ort.InferenceSession(m, options, providers=["CPUExecutionProvider"])

    def zeros(*shape):
        return np.zeros(shape, np.float32)

    # the raw snapshot is on the arm's graph; the incremental state on the model's own nodes
    # (fewer where an unknown-placement harness maps the sensors first)
    raw, features = meta["arm_graph"].n_nodes, schema.N_FEATURES
    if not incremental or "incremental_encode" not in meta:
        return onnx_flops(session, model, {"x": zeros(1, int(meta["window"]), raw, features)})
    nodes = int(meta["incremental_nodes"])
    g, f0 = int(meta["incremental_channels"]), int(meta["first_signal"])
    views = 3 * g + 7 * (features - f0) + f0
    state = zeros(1, nodes, features)
    encode = onnx_flops(
        session, base64.b64decode(meta["incremental_encode"]),
        {"x_new": zeros(1, raw, features), "z_prev": state, "z_first": state,
         "has_prev": zeros(1)},
    )  # fmt: skip
    head = onnx_flops(
        session, base64.b64decode(meta["incremental_head"]),
        {"views": zeros(1, nodes, views), "z_last": state},
    )  # fmt: skip
    return encode + head


def bench_profile(args: argparse.Namespace, x: np.ndarray) -> list[dict]:
    """Where the fleet step's time goes at each ``--profile`` stream count (unpaced), and the
    ONNX calls' FLOP rate against numpy's matmul rate measured in the same run."""
    cores = os.cpu_count() or 1
    flops = model_flops(args.model) / args.decide_every
    peak = sgemm_rate()
    print(
        f"\nprofile: {flops / 1e6:.3f} MFLOP per stream and tick in the ONNX calls; numpy sgemm "
        f"{peak / 1e9:.1f} GFLOP/s on {cores} cores ({peak / cores / 1e9:.1f} per core), measured "
        f"now; {args.profile_ticks} unpaced ticks after the windows fill"
    )
    rows = []
    for streams in args.profile:
        clock = PhaseClock()
        r = trial(args.model, x, streams, args.profile_ticks, shards=args.shards, clock=clock,
                  chunk=args.chunk, providers=args.providers,
                  decide_every=args.decide_every)  # fmt: skip
        per_tick = {k: v / args.profile_ticks * 1e3 for k, v in clock.seconds.items()}
        busy = sum(per_tick.values())
        onnx_s = sum(per_tick.get(k, 0.0) for k in ONNX_PHASES) / 1e3
        rate = flops * streams / onnx_s if onnx_s else float("nan")
        print(
            f"\n{streams} streams on {r['provider']}, {args.shards} shard threads, parts of <= "
            f"{args.chunk}: step "
            f"p50 {r['p50_ms']:.1f} ms, p99 {r['p99_ms']:.1f} ms; thread time {busy:.1f} ms "
            "per tick\n"
            "| phase | thread ms per tick | share |\n|---|---|---|"
        )
        for phase, ms in sorted(per_tick.items(), key=lambda kv: -kv[1]):
            print(f"| {phase} | {ms:.2f} | {ms / busy:.1%} |")
        print(
            f"ONNX calls: {rate / 1e9:.1f} GFLOP/s per busy thread = {rate / (peak / cores):.1%} "
            f"of one core's sgemm rate; the step's thread time is {busy / 1e3 / onnx_s:.2f}x "
            "the ONNX calls'"
        )
        rows.append({**r, "phases_ms": per_tick, "onnx_gflops_per_thread": rate / 1e9})
    return rows


def bench_compare(args: argparse.Namespace, x: np.ndarray) -> list[dict]:
    """What each of ``--compare``'s models costs per stream-tick and how many streams it
    sustains (the search), one after the other in this run, with ratios to the first (the
    reference): the cost frontier's deployment figures. int8 products count as FLOPs alike; a
    model run every k-th tick (``MODEL@k``) costs 1/k of its FLOPs per stream-tick."""
    from robohealth_mj.runtime.metadata import read_metadata

    rows = []
    for entry in args.compare:  # MODEL or MODEL@k: the model run every k-th tick of a stream
        model, _, every = entry.partition("@")
        k = int(every or 1)
        print(f"\n{entry} ({read_metadata(model)['model_id']}):", flush=True)
        found, _ = search(model, x, 100, start=args.start, shards=args.shards, chunk=args.chunk,
                          limit=args.limit, providers=args.providers, decide_every=k)  # fmt: skip
        rows.append({"model": entry, "mflop": model_flops(model) / 1e6 / k, "sustained": found})
    ref = rows[0]
    peak = sgemm_rate()
    print(
        f"\nsustained: the most streams with per-tick p99 <= {TICK_S * 1e3:.0f} ms (unpaced, "
        f"{args.shards} shard threads); ratios to {ref['model']}; numpy sgemm "
        f"{peak / 1e9:.1f} GFLOP/s on {os.cpu_count()} cores, measured after the searches\n"
        "| model | MFLOP per stream-tick | of the reference | sustained streams | x the reference |"
        "\n|---|---|---|---|---|"
    )
    for r in rows:
        print(
            f"| {r['model']} | {r['mflop']:.3f} | {r['mflop'] / ref['mflop']:.2f} | "
            f"{r['sustained']} | {r['sustained'] / max(ref['sustained'], 1):.2f} |"
        )
    return rows


def bench_fleet(args: argparse.Namespace) -> dict:
    """Search the sustained stream count, then a paced run at ``--streams``, then the windowed
    path at the same count; prints a markdown table."""
    x = _frames(args.data)
    cores = os.cpu_count() or 1
    asked = ", ".join(args.providers or ["default (CUDA if present, else CPU)"])
    print(
        f"{args.model}; {len(x)} recorded snapshots replayed from random offsets; {cores} cores, "
        f"{args.shards} shard threads; timed: FleetRuntime.step (validate, buffer, infer, alarms); "
        f"execution providers asked for: {asked}"
    )
    if args.profile:
        return {"profile": bench_profile(args, x)}
    if args.compare:
        return {"compare": bench_compare(args, x)}
    found = None
    if not args.no_search:
        print("search (unpaced, 100 ticks each after the windows fill):")
        found, _ = search(args.model, x, 100, start=args.start, shards=args.shards,
                          chunk=args.chunk, limit=args.limit, providers=args.providers,
                          decide_every=args.decide_every)  # fmt: skip
        print(f"sustained: {found} streams with per-tick p99 <= {TICK_S * 1e3:.0f} ms")
    ticks = round(args.seconds / TICK_S)
    common = {"shards": args.shards, "chunk": args.chunk, "providers": args.providers,
              "decide_every": args.decide_every}  # fmt: skip
    paced = trial(args.model, x, args.streams, ticks, paced=True, **common)
    windowed = trial(args.model, x, args.streams, 40, incremental=False, **common)
    print(
        "\n| path | streams | p50 ms | p99 ms | max ms | ticks over 50 ms | CPU (of all cores) |\n"
        "|---|---|---|---|---|---|---|"
    )
    print(_row(f"incremental, paced 20 Hz for {args.seconds:g} s", paced))
    print(_row("windowed (same runtime, whole window per tick), 40 ticks", windowed))
    memory = memory_cost(args, x) if args.memory_rounds > 0 else None
    return {"sustained_streams": found, "paced": paced, "windowed": windowed, "memory": memory}


def memory_cost(args: argparse.Namespace, x) -> dict:
    """The step with and without evidence accumulation at ``--streams``, unpaced, alternated
    (off, on, off, on) so that outside load falls on both alike; the ratio of their medians."""
    policy = EvidencePolicy(horizon_s=args.memory_horizon)
    runs: dict[str, list[dict]] = {"off": [], "on": []}
    for _ in range(args.memory_rounds):
        for key, evidence in (("off", None), ("on", policy)):
            runs[key].append(trial(args.model, x, args.streams, 200, shards=args.shards,
                                   evidence=evidence, chunk=args.chunk,
                                   providers=args.providers))  # fmt: skip
    p50 = {k: float(np.median([r["p50_ms"] for r in v])) for k, v in runs.items()}
    p99 = {k: float(np.median([r["p99_ms"] for r in v])) for k, v in runs.items()}
    print(
        f"\nmemory (evidence horizon {policy.horizon_s:g} s) at {args.streams} streams, unpaced, "
        f"{args.memory_rounds} x 200 ticks each, alternated:\n"
        f"| evidence | p50 ms | p99 ms |\n|---|---|---|\n"
        f"| off | {p50['off']:.2f} | {p99['off']:.2f} |\n"
        f"| on | {p50['on']:.2f} | {p99['on']:.2f} |\n"
        f"step time with memory / without: p50 {p50['on'] / p50['off']:.3f}, "
        f"p99 {p99['on'] / p99['off']:.3f}"
    )
    return {"p50_ms": p50, "p99_ms": p99, "ratio_p50": p50["on"] / p50["off"]}


def bench_soak(args: argparse.Namespace) -> dict:
    """A paced soak of ``--streams`` streams for ``--seconds`` under every bad-input kind."""
    x = _frames(args.data)
    fleet = FleetRuntime(
        args.model, threads=1, shards=args.shards, capacity=args.streams,
        max_streams=args.streams,
    )  # fmt: skip
    if fleet.engine is None:
        raise InputError(f"--model: {fleet.problem}")
    ticks = round(args.seconds / TICK_S)
    freeze_startup_heap()
    report = soak(fleet, x, args.streams, ticks, paced=True).summary()
    print(f"soak: {args.streams} streams, {ticks} ticks paced at 20 Hz, {report['rows']} rows")
    print("| bad-input kind | rows injected | not flagged with their reason |\n|---|---|---|")
    for kind, n in report["injected"].items():
        print(f"| {kind} | {n} | {report['missed'][kind]} |")
    print(
        f"healthy-stream rows without a decision after warm-up: {report['healthy_undecided']}\n"
        f"step p50 {report['step_p50_ms']:.1f} ms, p99 {report['step_p99_ms']:.1f} ms, max "
        f"{report['step_max_ms']:.1f} ms, {report['late_ticks']} ticks over 50 ms\n"
        f"resident memory {report['rss_start_mb']:.0f} MB after the first quarter -> "
        f"{report['rss_end_mb']:.0f} MB at the end ({report['rss_growth_mb']:+.1f} MB)"
    )
    return report
