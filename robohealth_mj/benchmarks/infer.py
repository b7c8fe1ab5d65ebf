"""Deployment benchmark: latency, batched throughput, FLOP share and sustained 20 Hz streams."""

from __future__ import annotations

import os
import tempfile
import time

import numpy as np

from robohealth_mj.benchmarks.common import fresh_variant, latency_ms, matmul_rate


def sustained_streams(
    model_path: str,
    window_x: np.ndarray,
    tick_budget_s: float = 0.05,
    start: int = 32,
    limit: int = 8192,
) -> tuple[int, dict[int, float]]:
    """Largest number of concurrent streams whose per-tick work (validate + buffer one sample per
    stream, one batched inference) fits in a 20 Hz tick, doubling N until it does not."""
    from robohealth_mj.data.jsonl import format_line
    from robohealth_mj.runtime.runtime import ModelRuntime
    from robohealth_mj.schema import FaultLabel

    segment = {"index": 0, "family": "whole_arm", "speed_scale": 1.0, "payload_scale": 1.0}
    w = window_x.shape[0]
    lines = [
        format_line(
            "bench", k, 0.05 * (k + 1), window_x[k % w].astype(float), FaultLabel(), segment
        )
        for k in range(w + 12)
    ]
    timings: dict[int, float] = {}
    best, n = 0, start
    while n <= limit:
        runtime = ModelRuntime(model_path)
        for k in range(w):  # fill every stream's window
            for s_id in range(n):
                runtime.submit(str(s_id), lines[k])
            runtime.tick()
        per_tick = []
        for k in range(w, w + 10):
            start_t = time.perf_counter()
            for s_id in range(n):
                runtime.submit(str(s_id), lines[k])
            runtime.tick()
            per_tick.append(time.perf_counter() - start_t)
        timings[n] = float(np.median(per_tick))
        if timings[n] > tick_budget_s:
            break
        best, n = n, n * 2
    return best, timings


def bench_infer(data: list[str], variants: list[str], window: int, batch: int) -> list[dict]:
    """Latency and throughput of every deployable variant on real held-out windows."""
    import onnxruntime as ort
    import torch
    from torch.utils.flop_counter import FlopCounterMode

    from robohealth_mj.data.arrays import load_recordings
    from robohealth_mj.data.windows import make_windows, normalisation
    from robohealth_mj.learn.trainer import expand_paths
    from robohealth_mj.models.onnx import export_onnx
    from robohealth_mj.runtime.export import RawInput, attach_metadata, model_metadata

    rec = load_recordings(expand_paths(data))
    windows = make_windows(rec, window)
    mean, std = normalisation(rec.x, windows)
    pick = np.linspace(0, len(windows) - 1, max(batch, 256)).astype(int)
    raw = torch.from_numpy(rec.x[windows.start[pick][:, None] + np.arange(window)])
    peak = matmul_rate()
    print(
        f"{len(raw)} held-out windows, W={window}; matmul rate {peak / 1e9:.0f} GFLOP/s; "
        f"batch-1: one thread, median/p95 of 200 calls after 10 warm-ups; batched: {batch}"
    )
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in variants:
            torch.manual_seed(0)
            model = fresh_variant(name, window).eval()
            pre = RawInput(torch.from_numpy(mean), torch.from_numpy(std), None).eval()
            with FlopCounterMode(display=False) as counter, torch.no_grad():
                model(pre(raw[:1]))
            flops = counter.get_total_flops()
            path = f"{tmp}/{name}.onnx"
            outputs = export_onnx(model, raw[:2], f"{path}.tmp", pre=pre)
            attach_metadata(
                f"{path}.tmp",
                path,
                model_metadata(
                    model_id=f"bench-{name}",
                    variant=name,
                    graph="structural",
                    window=window,
                    outputs=outputs,
                ),
            )
            one = ort.SessionOptions()
            one.intra_op_num_threads = 1
            s1 = ort.InferenceSession(path, one, providers=["CPUExecutionProvider"])
            sn = ort.InferenceSession(path, providers=ort.get_available_providers())
            torch.set_num_threads(1)
            k = iter(range(10**9))
            with torch.no_grad():
                t_eager = latency_ms(lambda m=model, p=pre, k=k: m(p(raw[next(k) % 256][None])))
            o_eager = latency_ms(
                lambda s=s1, k=k: s.run(None, {"x": raw[next(k) % 256][None].numpy()})
            )
            torch.set_num_threads(os.cpu_count() or 1)
            big = raw[:batch]
            big_np = big.numpy()
            with torch.no_grad():
                t_batch = batch / (
                    latency_ms(lambda m=model, p=pre, b=big: m(p(b)), 20, 3)[0] / 1e3
                )
            o_batch = batch / (
                latency_ms(lambda s=sn, b=big_np: s.run(None, {"x": b}), 20, 3)[0] / 1e3
            )
            streams, _ = sustained_streams(path, rec.x[windows.start[0] :][: window + 12])
            row = {
                "variant": name,
                "flops_per_window": flops,
                "torch_b1_ms": t_eager,
                "ort_b1_ms": o_eager,
                "torch_batched_wps": t_batch,
                "ort_batched_wps": o_batch,
                "ort_flop_fraction": o_batch * flops / peak,
                "streams_20hz": streams,
            }
            rows.append(row)
            print(
                f"{name:<20} {flops / 1e6:6.2f} MFLOP/win | batch-1 torch {t_eager[0]:.3f}/"
                f"{t_eager[1]:.3f} ms  ORT {o_eager[0]:.3f}/{o_eager[1]:.3f} ms (median/p95) | "
                f"batched torch {t_batch:,.0f}/s  ORT {o_batch:,.0f}/s = "
                f"{row['ort_flop_fraction']:.1%} of matmul | {streams} streams @20 Hz",
                flush=True,
            )
    return rows
