"""Helpers shared by the benchmarks: timing, the machine's matmul rate, a fresh variant."""

from __future__ import annotations

import time

import numpy as np


def latency_ms(fn, calls: int = 200, warmup: int = 10) -> tuple[float, float]:
    """Median and p95 wall time of ``calls`` calls after ``warmup`` untimed ones (ms)."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(calls):
        start = time.perf_counter()
        fn()
        times.append((time.perf_counter() - start) * 1e3)
    return float(np.median(times)), float(np.percentile(times, 95))


def _product_rate(a, b, seconds: float) -> float:
    """FLOP/s of ``a @ b`` (square, n x n) repeated for ``seconds`` after one warm-up."""
    a @ b
    calls, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        a @ b
        calls += 1
    return 2.0 * a.shape[0] ** 3 * calls / (time.perf_counter() - start)


def matmul_rate(seconds: float = 2.0, n: int = 1024) -> float:
    """Single-precision matmul FLOP/s of this machine (all torch threads)."""
    import torch

    return _product_rate(torch.randn(n, n), torch.randn(n, n), seconds)


def sgemm_rate(seconds: float = 2.0, n: int = 1024) -> float:
    """Single-precision matmul FLOP/s of this machine through numpy's BLAS (all its threads):
    the torch-free deployment install's yardstick."""
    rng = np.random.default_rng(0)
    return _product_rate(rng.random((n, n), np.float32), rng.random((n, n), np.float32), seconds)


MATMULS = ("MatMul", "MatMulInteger", "QLinearMatMul")  # A [.., M, K] times B [K, N]


def onnx_flops(session_factory, model: bytes | str, feeds: dict[str, np.ndarray]) -> float:
    """Multiply-add FLOPs (MatMul, Gemm, Einsum and the int8 products MatMulInteger and
    QLinearMatMul, counted alike; 2 per multiply-add) of one run of an ONNX model
    on ``feeds``, read off onnxruntime's own profile of that run: the shapes each node saw.
    ``session_factory(model, options)`` opens the session (so the caller picks providers);
    ``feeds`` may hold more inputs than the graph takes (an incremental encode without
    ``z_first``)."""
    import json
    import os

    import onnx
    import onnxruntime as ort

    proto = onnx.load_from_string(model) if isinstance(model, bytes) else onnx.load(model)
    equations = {
        n.name: onnx.helper.get_attribute_value(n.attribute[0]).decode()
        for n in proto.graph.node
        if n.op_type == "Einsum"
    }
    options = ort.SessionOptions()
    options.enable_profiling = True
    options.graph_optimization_level = ort.GraphOptimizationLevel.ORT_DISABLE_ALL
    session = session_factory(model, options)
    try:
        session.run(None, {i.name: feeds[i.name] for i in session.get_inputs()})
    except BaseException:  # no profile file left behind in the caller's directory
        os.remove(session.end_profiling())
        raise
    path = session.end_profiling()
    try:
        with open(path) as f:
            events = json.load(f)
    finally:
        os.remove(path)
    total = 0.0
    for e in events:
        args = e.get("args", {})
        op = args.get("op_name")
        if e.get("cat") != "Node" or op not in ("Gemm", "Einsum", *MATMULS):
            continue
        shapes = [next(iter(d.values())) for d in args["input_type_shape"]]
        out = next(iter(args["output_type_shape"][0].values()))
        if op == "Einsum":
            sizes: dict[str, int] = {}
            terms = equations[e["name"].removesuffix("_kernel_time")].split("->")[0].split(",")
            for term, shape in zip(terms, shapes, strict=True):
                sizes.update(zip(term, shape, strict=True))
            total += 2.0 * float(np.prod(list(sizes.values())))
        else:
            rows = float(np.prod(out[:-1]))
            a = shapes[0]
            inner = float(np.prod(a)) / rows if op in MATMULS else float(np.prod(a)) / out[0]
            total += 2.0 * rows * out[-1] * inner
    return total


def fresh_variant(name: str, window: int, *overrides: str):
    """A freshly initialised model of a variant as ``train`` composes it (model + backbone) on
    the schema graph."""
    from robohealth_mj import schema
    from robohealth_mj.common.config import compose_config
    from robohealth_mj.models import build_model

    cfg = compose_config("train", [f"variant={name}", *overrides])
    return build_model(cfg.model, schema.adjacency(), schema.N_JOINTS, schema.N_FEATURES, window)
