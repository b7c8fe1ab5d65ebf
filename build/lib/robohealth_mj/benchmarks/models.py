"""Model benchmark: parameters and batch-1 CPU latency (PyTorch eager, onnxruntime) per variant."""

from __future__ import annotations

import tempfile

from robohealth_mj.benchmarks.common import fresh_variant, latency_ms


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
                model = fresh_variant(name, window).eval()
                x = torch.randn(1, window, schema.N_NODES, schema.N_FEATURES)
                with torch.no_grad():
                    eager = latency_ms(lambda m=model, x=x: m(x))
                path = f"{tmp}/{name}_{window}.onnx"
                export_onnx(model, x.repeat(2, 1, 1, 1), path)
                session = ort.InferenceSession(path, options, providers=["CPUExecutionProvider"])
                feed = {"x": x.numpy()}
                onnx = latency_ms(lambda s=session, f=feed: s.run(None, f))
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
