"""Deployment benchmark: batch-1 latency, batched throughput and FLOP share, per variant (fresh
weights) or of one exported model (``--model``: the headline). Stream capacity: ``bench
streams``."""

from __future__ import annotations

import os
import tempfile

import numpy as np

from robohealth_mj.benchmarks.common import fresh_variant, latency_ms, matmul_rate


def bench_infer(data: list[str], variants: list[str], window: int, batch: int) -> list[dict]:
    """Latency and throughput of every deployable variant on real held-out windows."""
    import onnxruntime as ort
    import torch
    from torch.utils.flop_counter import FlopCounterMode

    from robohealth_mj.data.arrays import expand_paths, load_recordings
    from robohealth_mj.data.windows import make_windows, normalisation
    from robohealth_mj.deploy.export import RawInput, attach_metadata, model_metadata
    from robohealth_mj.models.onnx import export_onnx

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
            row = {
                "variant": name,
                "flops_per_window": flops,
                "torch_b1_ms": t_eager,
                "ort_b1_ms": o_eager,
                "torch_batched_wps": t_batch,
                "ort_batched_wps": o_batch,
                "ort_flop_fraction": o_batch * flops / peak,
            }
            rows.append(row)
            print(
                f"{name:<20} {flops / 1e6:6.2f} MFLOP/win | batch-1 torch {t_eager[0]:.3f}/"
                f"{t_eager[1]:.3f} ms  ORT {o_eager[0]:.3f}/{o_eager[1]:.3f} ms (median/p95) | "
                f"batched torch {t_batch:,.0f}/s  ORT {o_batch:,.0f}/s = "
                f"{row['ort_flop_fraction']:.1%} of matmul",
                flush=True,
            )
    return rows


def bench_deployed(model_path: str, data: list[str], batch: int) -> dict:
    """One exported model: onnxruntime batch-1 latency on one thread (the windowed graph, and a
    fleet step of one stream with the incremental form), and the batched windowed path's
    throughput as a share of the matmul rate measured in the same run."""
    import onnxruntime as ort
    import torch
    from torch.utils.flop_counter import FlopCounterMode

    from robohealth_mj.data.arrays import expand_paths, load_recordings
    from robohealth_mj.data.windows import make_windows
    from robohealth_mj.runtime.fleet import FleetRuntime
    from robohealth_mj.runtime.metadata import read_metadata

    meta = read_metadata(model_path)
    window = int(meta["window"])
    rec = load_recordings(expand_paths(data))
    windows = make_windows(rec, window)
    pick = np.linspace(0, len(windows) - 1, max(batch, 256)).astype(int)
    raw = rec.x[windows.start[pick][:, None] + np.arange(window)]
    torch.manual_seed(0)
    model = fresh_variant(meta["variant"], window).eval()  # same architecture: same FLOPs
    with FlopCounterMode(display=False) as counter, torch.no_grad():
        model(torch.from_numpy(raw[:1]))
    flops = counter.get_total_flops()
    peak = matmul_rate()
    one = ort.SessionOptions()
    one.intra_op_num_threads = 1
    s1 = ort.InferenceSession(model_path, one, providers=["CPUExecutionProvider"])
    sn = ort.InferenceSession(model_path, providers=ort.get_available_providers())
    k = iter(range(10**9))
    b1 = latency_ms(lambda: s1.run(None, {"x": raw[next(k) % len(raw)][None]}), 1000, 50)
    big = raw[:batch]
    batched = batch / (latency_ms(lambda: sn.run(None, {"x": big}), 20, 3)[0] / 1e3)
    fleet = FleetRuntime(model_path, threads=1)
    slot = fleet.register(["one"])
    x = rec.x
    for t in range(window):  # fill the window
        fleet.step(slot, np.array([t]), np.array([0.05 * (t + 1)]), x[t : t + 1])
    step = iter(range(window, 10**9))

    def one_tick() -> None:
        t = next(step)
        fleet.step(slot, np.array([t]), np.array([0.05 * (t + 1)]), x[t % len(x)][None])

    tick = latency_ms(one_tick, 1000, 50)
    row = {
        "model": model_path,
        "model_id": meta["model_id"],
        "window": window,
        "flops_per_window": flops,
        "matmul_gflops": peak / 1e9,
        "ort_b1_ms": b1,
        "fleet_step_1_stream_ms": tick,
        "fleet_mode": fleet.mode,
        "ort_batched_wps": batched,
        "ort_flop_fraction": batched * flops / peak,
    }
    print(
        f"{meta['model_id']} (W={window}, {flops / 1e6:.2f} MFLOP/window); matmul rate "
        f"{peak / 1e9:.0f} GFLOP/s\n"
        f"  onnxruntime batch-1, one thread: median {b1[0]:.3f} ms, p95 {b1[1]:.3f} ms "
        f"(targets 0.3 / 0.6; 1000 calls after 50 warm-ups)\n"
        f"  fleet step of one stream ({fleet.mode}): median {tick[0]:.3f} ms, "
        f"p95 {tick[1]:.3f} ms\n"
        f"  batched ({batch} windows, all threads): {batched:,.0f} windows/s = "
        f"{row['ort_flop_fraction']:.1%} of the matmul rate",
        flush=True,
    )
    return row
