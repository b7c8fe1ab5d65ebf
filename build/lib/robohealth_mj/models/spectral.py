"""Window spectral features computed inside the model, so the variant exports and deploys.

Per node: RMS, peak, spectral centroid and high-band energy ratio of the vibration channel, and the
RMS of the accelerometer magnitude. The DFT is a fixed matrix (a buffer), so ONNX sees matmuls.

Shapes: ``x [B, W, N, F]`` -> ``[B, N, 5]``.
"""

from __future__ import annotations

import math

import torch
from torch import nn

from robohealth_mj import schema

NUM_SPECTRAL = 5


class SpectralFeatures(nn.Module):
    def __init__(
        self,
        window: int,
        vib_index: int = schema.feature_index("vib"),
        acc_indices: tuple[int, ...] = tuple(
            schema.feature_index(a) for a in ("acc_x", "acc_y", "acc_z")
        ),
        high_band: float = 0.5,
    ) -> None:
        super().__init__()
        self.vib_index, self.acc_indices = vib_index, list(acc_indices)
        bins = window // 2 + 1
        t = torch.arange(window, dtype=torch.float32)
        k = torch.arange(bins, dtype=torch.float32)
        angle = 2.0 * math.pi * t[:, None] * k[None, :] / window
        self.register_buffer("cos", torch.cos(angle))  # [W, K]
        self.register_buffer("sin", torch.sin(angle))
        freq = k / window  # cycles per sample, 0 .. 0.5
        self.register_buffer("freq", freq)
        self.register_buffer("high", (freq >= high_band * 0.5).float())

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        vib = x[..., self.vib_index].transpose(1, 2)  # [B, N, W]
        rms = vib.square().mean(-1).sqrt()
        peak = vib.abs().amax(-1)
        centred = vib - vib.mean(-1, keepdim=True)
        power = (centred @ self.cos).square() + (centred @ self.sin).square()  # [B, N, K]
        total = power.sum(-1) + 1e-6
        centroid = (power * self.freq).sum(-1) / total
        high_ratio = (power * self.high).sum(-1) / total
        acc = x[..., self.acc_indices]  # [B, W, N, 3]
        acc_rms = acc.square().sum(-1).mean(1).sqrt()  # [B, N]
        return torch.stack([rms, peak, centroid, high_ratio, acc_rms], dim=-1)
