"""``python -m robohealth_mj.bench``: throughput benchmarks (not tests).

    python -m robohealth_mj.bench sim [--duration 60]
    python -m robohealth_mj.bench models [--windows 16 32] [--variants anomaly_residual ...]
    python -m robohealth_mj.bench train [--data 'outputs/corpus/quick/train_*'] [--window 16]
    python -m robohealth_mj.bench infer [--data outputs/corpus/quick/heldout_seed900] [--window 32]

``sim`` measures, in one run, the raw ``mj_step`` rate of the scene and the recorder's throughput
(physics + control + sensor synthesis + JSONL writing), and reports their ratio.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import mujoco
import numpy as np

from robohealth_mj.config import compose_config
from robohealth_mj.recorder import build_simulator, record_session


def raw_step_rate(model: mujoco.MjModel, data: mujoco.MjData, seconds: float = 3.0) -> float:
    """Physics steps per wall second with steps batched in C (``mj_step`` with ``nstep``)."""
    batch = 1000
    mujoco.mj_step(model, data, nstep=batch)  # warm-up
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        mujoco.mj_step(model, data, nstep=batch)
        steps += batch
    return steps / (time.perf_counter() - start)


def bench_sim(duration_s: float, overrides: list[str]) -> dict[str, float]:
    cfg = compose_config(
        "record", [f"session.duration_s={duration_s}", "session.progress=false", *overrides]
    )
    sim = build_simulator(cfg)
    data = mujoco.MjData(sim.model)
    data.qpos[:] = sim.data.qpos
    data.ctrl[:] = sim.data.qpos[sim.index.motor_qpos]
    steps_per_s = raw_step_rate(sim.model, data)
    with tempfile.TemporaryDirectory() as tmp:
        result = record_session(cfg, tmp)
    sim_s = result.manifest["sample_count"] / result.manifest["rates"]["tick_hz"]
    recorder_rate = sim_s / result.wall_s
    raw_sim_s = steps_per_s * sim.dt
    return {
        "raw_steps_per_s": steps_per_s,
        "raw_sim_s_per_s": raw_sim_s,
        "recorder_sim_s_per_s": recorder_rate,
        "ratio": recorder_rate / raw_sim_s,
    }


def _variant(name: str, window: int):
    """A freshly initialised model of ``conf/model/<name>.yaml`` on the schema graph."""
    from omegaconf import OmegaConf

    from robohealth_mj import schema
    from robohealth_mj.config import CONF_DIR
    from robohealth_mj.models import build_model

    cfg = OmegaConf.load(CONF_DIR / "model" / f"{name}.yaml")
    return build_model(cfg, schema.adjacency(), schema.N_JOINTS, schema.N_FEATURES, window)


def _latency_ms(fn, calls: int = 200, warmup: int = 10) -> tuple[float, float]:
    """Median and p95 wall time of ``calls`` calls after ``warmup`` untimed ones (ms)."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(calls):
        start = time.perf_counter()
        fn()
        times.append((time.perf_counter() - start) * 1e3)
    return float(np.median(times)), float(np.percentile(times, 95))


def bench_models(windows: list[int], variants: list[str]) -> list[dict]:
    """Parameter count and batch-1 latency (PyTorch eager, onnxruntime) per variant and window."""
    import onnxruntime as ort
    import torch

    from robohealth_mj import schema
    from robohealth_mj.models.onnx import export_onnx

    torch.set_num_threads(1)
    options = ort.SessionOptions()
    options.intra_op_num_threads = 1
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in variants:
            for window in windows:
                torch.manual_seed(0)
                model = _variant(name, window).eval()
                x = torch.randn(1, window, schema.N_NODES, schema.N_FEATURES)
                with torch.no_grad():
                    eager = _latency_ms(lambda m=model, x=x: m(x))
                path = f"{tmp}/{name}_{window}.onnx"
                export_onnx(model, x.repeat(2, 1, 1, 1), path)
                session = ort.InferenceSession(path, options, providers=["CPUExecutionProvider"])
                feed = {"x": x.numpy()}
                onnx = _latency_ms(lambda s=session, f=feed: s.run(None, f))
                rows.append(
                    {
                        "variant": name,
                        "window": window,
                        "params": sum(p.numel() for p in model.parameters()),
                        "torch_median_ms": eager[0],
                        "torch_p95_ms": eager[1],
                        "ort_median_ms": onnx[0],
                        "ort_p95_ms": onnx[1],
                    }
                )
                print(
                    f"{name:<20} W={window:<3} {rows[-1]['params']:>8,} params  "
                    f"torch {eager[0]:6.3f} ms (p95 {eager[1]:6.3f})  "
                    f"onnxruntime {onnx[0]:6.3f} ms (p95 {onnx[1]:6.3f})",
                    flush=True,
                )
    return rows


def matmul_rate(seconds: float = 2.0, n: int = 1024) -> float:
    """Single-precision matmul FLOP/s of this machine (all torch threads)."""
    import torch

    a, b = torch.randn(n, n), torch.randn(n, n)
    a @ b
    calls, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        a @ b
        calls += 1
    return 2.0 * n**3 * calls / (time.perf_counter() - start)


def bench_train(
    data: list[str], variants: list[str], window: int, steps: int, batch: int
) -> list[dict]:
    """Training throughput per variant on real windows; data loading timed separately."""
    import torch
    from torch.utils.flop_counter import FlopCounterMode

    from robohealth_mj.config import compose_config
    from robohealth_mj.data.arrays import load_recordings
    from robohealth_mj.data.windows import make_windows, normalisation
    from robohealth_mj.learn.data import WindowTensors
    from robohealth_mj.learn.loss import training_loss
    from robohealth_mj.learn.trainer import expand_paths

    t0 = time.perf_counter()
    rec = load_recordings(expand_paths(data))
    load_s = time.perf_counter() - t0
    windows = make_windows(rec, window)
    mean, std = normalisation(rec.x, windows)
    tensors = WindowTensors(rec.x, rec, mean, std, torch.device("cpu"))
    peak = matmul_rate()
    weights = compose_config("train").trainer
    print(
        f"data: {len(rec)} samples, {len(windows)} windows; loading from the binary cache "
        f"{load_s:.2f} s; matmul rate {peak / 1e9:.0f} GFLOP/s; batch {batch}, W={window}"
    )
    rows = []
    rng = np.random.default_rng(0)
    for name in variants:
        torch.manual_seed(0)
        model = _variant(name, window)
        opt = torch.optim.Adam(model.parameters(), lr=1e-3)

        def step(b, model=model, opt=opt):
            loss, _ = training_loss(
                model(b.x),
                b,
                weights.joint_loss_weight,
                weights.recon_loss_weight,
                weights.severity_loss_weight,
            )
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()

        first = tensors.batch(windows, rng.integers(0, len(windows), batch))
        with FlopCounterMode(display=False) as counter:
            step(first)
        flops_per_window = counter.get_total_flops() / batch
        for _ in range(3):
            step(first)
        gather = compute = 0.0
        for _ in range(steps):
            t = time.perf_counter()
            b = tensors.batch(windows, rng.integers(0, len(windows), batch))
            gather += time.perf_counter() - t
            t = time.perf_counter()
            step(b)
            compute += time.perf_counter() - t
        total = gather + compute
        rate = steps * batch / total
        row = {
            "variant": name,
            "windows_per_s": rate,
            "data_share": gather / total,
            "flops_per_window": flops_per_window,
            "flop_fraction": rate * flops_per_window / peak,
        }
        rows.append(row)
        print(
            f"{name:<20} {rate:>8,.0f} windows/s  data {row['data_share']:6.1%}  "
            f"{flops_per_window / 1e6:6.1f} MFLOP/window  {row['flop_fraction']:6.1%} of "
            f"matmul rate",
            flush=True,
        )
    return rows


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
            model = _variant(name, window).eval()
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
                t_eager = _latency_ms(lambda m=model, p=pre, k=k: m(p(raw[next(k) % 256][None])))
            o_eager = _latency_ms(
                lambda s=s1, k=k: s.run(None, {"x": raw[next(k) % 256][None].numpy()})
            )
            torch.set_num_threads(os.cpu_count() or 1)
            big = raw[:batch]
            big_np = big.numpy()
            with torch.no_grad():
                t_batch = batch / (
                    _latency_ms(lambda m=model, p=pre, b=big: m(p(b)), 20, 3)[0] / 1e3
                )
            o_batch = batch / (
                _latency_ms(lambda s=sn, b=big_np: s.run(None, {"x": b}), 20, 3)[0] / 1e3
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


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.bench",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="what", required=True)
    sim = sub.add_parser("sim", help="raw mj_step rate vs recorder throughput")
    sim.add_argument("--duration", type=float, default=60.0, help="simulated seconds to record")
    sim.add_argument("overrides", nargs="*", help="Hydra overrides for conf/record.yaml")
    models = sub.add_parser("models", help="parameters and batch-1 CPU latency per variant")
    models.add_argument("--windows", type=int, nargs="+", default=[16, 32])
    models.add_argument(
        "--variants", nargs="+", default=None, help="default: every conf/model/*.yaml"
    )
    train = sub.add_parser("train", help="training throughput per variant")
    train.add_argument("--data", nargs="+", default=["outputs/corpus/quick/train_*"])
    train.add_argument("--variants", nargs="+", default=["mlp", "stgnn_fixed", "anomaly_residual"])
    train.add_argument("--window", type=int, default=16)
    train.add_argument("--steps", type=int, default=20)
    train.add_argument("--batch", type=int, default=128)
    infer = sub.add_parser("infer", help="deployment latency, throughput and stream capacity")
    infer.add_argument("--data", nargs="+", default=["outputs/corpus/quick/heldout_seed900"])
    infer.add_argument(
        "--variants", nargs="+", default=None, help="default: every conf/model/*.yaml"
    )
    infer.add_argument("--window", type=int, default=32)
    infer.add_argument("--batch", type=int, default=256)
    args = parser.parse_args(argv)
    if args.what == "infer":
        from robohealth_mj.models import VARIANTS

        bench_infer(args.data, args.variants or list(VARIANTS), args.window, args.batch)
        return
    if args.what == "train":
        bench_train(args.data, args.variants, args.window, args.steps, args.batch)
        return
    if args.what == "models":
        from robohealth_mj.config import CONF_DIR

        variants = args.variants or sorted(p.stem for p in (CONF_DIR / "model").glob("*.yaml"))
        print("batch-1 latency on one CPU thread: median and p95 of 200 calls after 10 warm-ups")
        bench_models(args.windows, variants)
        return
    if args.what == "sim":
        r = bench_sim(args.duration, args.overrides)
        print(
            f"raw mj_step rate      {r['raw_steps_per_s']:>10.0f} steps/s "
            f"({r['raw_sim_s_per_s']:.1f} sim s per wall s)"
        )
        print(
            f"recorder throughput   {r['recorder_sim_s_per_s']:>10.1f} sim s per wall s "
            f"({r['recorder_sim_s_per_s']:.0f}x real time)"
        )
        print(f"recorder / raw        {r['ratio']:>10.1%}   (target >= 50%)")
        np.testing.assert_(r["ratio"] > 0)


if __name__ == "__main__":
    main()
