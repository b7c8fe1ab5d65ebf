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


def fresh_variant(name: str, window: int, *overrides: str):
    """A freshly initialised model of a variant as ``train`` composes it (model + backbone) on
    the schema graph."""
    from robohealth_mj import schema
    from robohealth_mj.common.config import compose_config
    from robohealth_mj.models import build_model

    cfg = compose_config("train", [f"variant={name}", *overrides])
    return build_model(cfg.model, schema.adjacency(), schema.N_JOINTS, schema.N_FEATURES, window)
