"""Window statistics per node and signal channel: what the classical baseline sees, and one of the
two views the window encoder has of a window.

For each signal channel (everything after the node-type flags): mean, std, min, max, last - first,
mean |Δ| and max |Δ| over the window. Plain tensor ops, so the networks that use them export.

Shapes: ``x [B, W, N, F]`` -> ``[B, N, S * 7]`` with ``S = F - first_signal``.
"""

from __future__ import annotations

import torch

from robohealth_mj.schema import WINDOW_STATISTICS as STATISTICS

NUM_STATISTICS = len(STATISTICS)


def window_statistics(x: torch.Tensor, first_signal: int = 2) -> torch.Tensor:
    """``[B, W, N, F]`` -> ``[B, N, S * 7]``, statistics-major within each channel."""
    s = x[..., first_signal:]  # [B, W, N, S]
    mean = s.mean(1)
    std = (s - mean.unsqueeze(1)).square().mean(1).clamp_min(1e-12).sqrt()
    step = (s[:, 1:] - s[:, :-1]).abs()
    stats = torch.stack(
        [mean, std, s.amin(1), s.amax(1), s[:, -1] - s[:, 0], step.mean(1), step.amax(1)],
        dim=-1,
    )  # [B, N, S, 7]
    return stats.flatten(-2)


def statistic_names(channels: tuple[str, ...]) -> list[str]:
    """Column names of :func:`window_statistics` for the given signal channel names."""
    return [f"{c}.{s}" for c in channels for s in STATISTICS]
