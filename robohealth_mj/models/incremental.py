"""The incremental (streaming) form of the default window backbone: a tick costs one snapshot.

The window encoder sees a window only through pooled views: mean, std and max over time of a
per-snapshot MLP ``g([z_t, z_t - z_{t-1}])``, and window statistics of the normalised signals.
Every one of them is a sum, a sum of squares, a minimum or a maximum over the window's snapshots,
so a stream can keep per-snapshot records in a ring and the sums running, and the network proper
runs only twice per tick:

- ``SnapshotStep`` (one snapshot): raw sample -> normalised ``z``, its record ``g`` (with the
  step from the previous sample) and, where the encoder pools the window's oldest snapshot too
  (``first_record``), ``g`` of the window's new oldest snapshot with a zero step (the windowed
  encoder gives the oldest snapshot of a window no step); without it each sample's record is
  computed once and the oldest snapshot's record simply leaves the pool;
- ``PooledHead`` (one window's pooled views): the encoder's projection, message passing and the
  output heads, shared with :class:`~robohealth_mj.models.stgnn.STGNN` itself.

The pooling between them lives in :mod:`robohealth_mj.runtime.incremental`; a test holds the
whole chain equal to the windowed model.

Shapes: ``SnapshotStep``: ``x_new [B, N, F]`` raw, ``z_prev [B, N, F]`` normalised, ``has_prev
[B]`` (and ``z_first [B, N, F]`` with ``first_record``) -> ``z_new [B, N, F]``, ``g_new [B, N,
G]`` (and ``g_first [B, N, G]``). ``PooledHead``:
``views [B, N, 3G + 7S + 2]`` (the encoder's pooled views in its order: mean, std and max of
``g``; the window statistics, asinh-compressed; the node-type flags), ``z_last [B, N, F]`` ->
class and joint logits. The runtime assembles the views in numpy, in one buffer (no concat
node), and takes the asinh there (onnxruntime's Asinh kernel is scalar and slow).
"""

from __future__ import annotations

import torch
from torch import nn

from robohealth_mj.models.backbone import WindowBackbone
from robohealth_mj.models.onnx import OUTPUTS


def supports_incremental(model: nn.Module) -> bool:
    """True for an STGNN on the window backbone whose encoder is pooled views only (statistics and
    snapshot MLP; no temporal convolutions, no window spectrum)."""
    backbone = getattr(model, "backbone", None)
    if not isinstance(backbone, WindowBackbone) or getattr(model, "spectral", None) is not None:
        return False
    enc = backbone.encoder
    return enc.conv is None and enc.snapshot is not None and enc.statistics


class SnapshotStep(nn.Module):
    """One raw snapshot -> its normalised values and per-snapshot MLP records."""

    def __init__(self, model: nn.Module, pre: nn.Module) -> None:
        super().__init__()
        self.pre = pre
        self.snapshot = model.backbone.encoder.snapshot
        self.first_record = model.backbone.encoder.first_record

    @property
    def input_names(self) -> list[str]:
        return ["x_new", "z_prev", "has_prev"] + (["z_first"] if self.first_record else [])

    @property
    def output_names(self) -> list[str]:
        return ["z_new", "g_new"] + (["g_first"] if self.first_record else [])

    def forward(
        self,
        x_new: torch.Tensor,
        z_prev: torch.Tensor,
        has_prev: torch.Tensor,
        z_first: torch.Tensor | None = None,
    ) -> tuple[torch.Tensor, ...]:
        z_new = self.pre(x_new.unsqueeze(1)).squeeze(1)
        step = (z_new - z_prev) * has_prev[:, None, None]
        g_new = self.snapshot(torch.cat([z_new, step], dim=-1))
        if z_first is None:
            return z_new, g_new
        g_first = self.snapshot(torch.cat([z_first, torch.zeros_like(z_first)], dim=-1))
        return z_new, g_new, g_first


class PooledHead(nn.Module):
    """Pooled views of one window -> the model's outputs (projection, graph, heads)."""

    def __init__(self, model: nn.Module) -> None:
        super().__init__()
        self.model = model
        self.encoder = model.backbone.encoder
        self.has_severity = getattr(model, "severity", None) is not None

    @property
    def output_names(self) -> list[str]:
        return list(OUTPUTS[: 3 if self.has_severity else 2])

    def forward(self, views: torch.Tensor, z_last: torch.Tensor) -> tuple[torch.Tensor, ...]:
        skip = self.model.placed(self.encoder.embed([views]))
        positions = z_last[..., self.model.pos_index]
        adj = self.model.edges(positions)
        refined, temporal, skip = self.model.backbone.message_passing(skip, adj)
        out = self.model.heads(positions, refined, temporal, skip)
        return tuple(out[name] for name in self.output_names)
