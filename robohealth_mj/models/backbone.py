"""Spatio-temporal backbones: the default window backbone and the thesis's per-snapshot one.

Both take node features ``x [B, W, N, F]`` and per-sample edge weights ``adj [B, N, N]`` and return
``(refined, temporal, skip)``, each ``[B, N, H]``:

- ``skip``: each node's own evidence before any message passing (localisation reads it so that one
  sensor's evidence is not averaged away);
- ``temporal``: after message passing (the anomaly-residual head reads it);
- ``refined``: after the optional cross-node self-attention (classifier and localisation).

``graph_conv`` is a factory for one message-passing layer (``GCNBlock`` or ``GATBlock``), or None
for no cross-node pathway at all (the ``mlp`` control). Chosen with ``backbone=window|thesis``.
"""

from __future__ import annotations

from collections.abc import Callable

import torch
from torch import nn
from torch_geometric.nn import DenseGATConv, DenseGCNConv

from robohealth_mj.models.statistics import NUM_STATISTICS, window_statistics

GraphConvFactory = Callable[..., nn.Module]


class TimeSharedDropout(nn.Module):
    """Dropout with one mask per (window, node, channel), shared across the window's snapshots
    (variational dropout); ``window=1`` is ordinary dropout."""

    def __init__(self, p: float) -> None:
        super().__init__()
        self.p = float(p)

    def forward(self, h: torch.Tensor, window: int = 1) -> torch.Tensor:
        if not self.training or self.p == 0.0:
            return h
        bw, n, c = h.shape
        keep = torch.rand(bw // window, 1, n, c, device=h.device) >= self.p
        mask = keep.to(h.dtype).div_(1.0 - self.p)
        return (h.reshape(-1, window, n, c) * mask).reshape(bw, n, c)


class GraphBlock(nn.Module):
    """One message-passing layer + LayerNorm, ReLU, dropout and a residual skip."""

    def __init__(self, conv: nn.Module, hidden: int, dropout: float) -> None:
        super().__init__()
        self.conv = conv
        self.norm = nn.LayerNorm(hidden)
        self.dropout = TimeSharedDropout(dropout)

    def forward(self, h: torch.Tensor, adj: torch.Tensor, window: int = 1) -> torch.Tensor:
        return h + self.dropout(torch.relu(self.norm(self.conv(h, adj))), window)


class GCNBlock(GraphBlock):
    """Dense GCN on the per-sample edge weights (self-loops, symmetric normalisation)."""

    def __init__(self, hidden: int, dropout: float, heads: int = 1) -> None:
        del heads
        super().__init__(DenseGCNConv(hidden, hidden), hidden, dropout)


class GATBlock(GraphBlock):
    """Multi-head dense graph attention over the mask (implicit edge weights)."""

    def __init__(self, hidden: int, dropout: float, heads: int = 4) -> None:
        conv = DenseGATConv(hidden, hidden, heads=heads, concat=False, dropout=dropout)
        super().__init__(conv, hidden, dropout)


def _attention(hidden: int, heads: int, dropout: float) -> nn.Module:
    return nn.TransformerEncoderLayer(
        hidden, heads, dim_feedforward=2 * hidden, dropout=dropout, batch_first=True
    )


def _with_zero_step(step: torch.Tensor) -> torch.Tensor:
    """``[B, W - 1, ...]`` steps -> ``[B, W, ...]``, the oldest snapshot's step zero."""
    return torch.cat([torch.zeros_like(step[:, :1]), step], dim=1)


class WindowEncoder(nn.Module):
    """Per-node temporal encoder shared by all nodes; it sees the whole window at once.

    Up to three views of each node's window, concatenated and put through an MLP:

    - window statistics of the raw channels (compressed with asinh, since jam impulses make them
      heavy-tailed);
    - a per-snapshot MLP over each snapshot and its first difference ``[x_t, x_t - x_{t-1}]``,
      pooled by mean, std and max over time: learned nonlinear mixes of channels (effort against
      the sign of velocity, say) that no per-channel statistic holds, at matmul cost. With
      ``first_record`` the window's oldest snapshot is pooled too, with a zero step; without it
      only the W - 1 snapshots that have a step are, so a streaming monitor computes each
      snapshot's record once (:mod:`robohealth_mj.models.incremental`), not twice;
    - dilated temporal convolutions pooled the same way (longer local patterns; 4x slower).

    A learned per-node embedding then tells the shared encoder's output which node it came from.

    Shapes: ``x [B, W, N, F]`` -> ``[B, N, H]``.
    """

    def __init__(
        self,
        in_features: int,
        num_nodes: int,
        hidden: int,
        dropout: float,
        channels: int = 16,
        kernel: int = 5,
        convolutions: bool = False,
        statistics: bool = True,
        snapshot_mlp: bool = True,
        node_embedding: bool = True,
        first_signal: int = 2,
        first_record: bool = True,
    ) -> None:
        super().__init__()
        if not (convolutions or statistics or snapshot_mlp):
            raise ValueError("the window encoder needs statistics, a snapshot MLP or convolutions")
        self.first_signal = first_signal
        self.first_record = first_record
        pad = kernel // 2
        self.conv = (
            nn.Sequential(
                nn.Conv1d(in_features, channels, kernel, padding=pad),
                nn.GELU(),
                nn.Conv1d(channels, channels, kernel, padding=2 * pad, dilation=2),
                nn.GELU(),
            )
            if convolutions
            else None
        )
        self.snapshot = (
            nn.Sequential(
                nn.Linear(2 * in_features, channels),
                nn.GELU(),
                nn.Linear(channels, channels),
                nn.GELU(),
            )
            if snapshot_mlp
            else None
        )
        signals = in_features - first_signal
        width = (
            (3 * channels if convolutions else 0)
            + (3 * channels if snapshot_mlp else 0)
            + (signals * NUM_STATISTICS + first_signal if statistics else 0)
        )
        self.statistics = statistics
        self.project = nn.Sequential(
            nn.Linear(width, hidden),
            nn.LayerNorm(hidden),
            nn.GELU(),
            nn.Dropout(dropout),
            nn.Linear(hidden, hidden),
        )
        self.node = nn.Parameter(torch.zeros(num_nodes, hidden)) if node_embedding else None

    @staticmethod
    def _pool(seq: torch.Tensor, dim: int) -> torch.Tensor:
        """Mean, std and max over the time axis ``dim``, concatenated on the last axis."""
        mean = seq.mean(dim)
        std = (seq - mean.unsqueeze(dim)).square().mean(dim).clamp_min(1e-12).sqrt()
        return torch.cat([mean, std, seq.amax(dim)], dim=-1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        b, w, n, f = x.shape
        views = []
        if self.snapshot is not None:
            step = x[:, 1:] - x[:, :-1]
            if self.first_record:
                views.append(
                    self._pool(self.snapshot(torch.cat([x, _with_zero_step(step)], -1)), 1)
                )
            else:
                views.append(self._pool(self.snapshot(torch.cat([x[:, 1:], step], -1)), 1))
        if self.conv is not None:
            seq = self.conv(x.permute(0, 2, 3, 1).reshape(b * n, f, w))  # [B*N, C, W]
            views.append(self._pool(seq.transpose(1, 2), 1).reshape(b, n, -1))
        if self.statistics:
            views.append(torch.asinh(window_statistics(x, self.first_signal)))
            views.append(x[:, -1, :, : self.first_signal])  # node-type flags
        return self.embed(views)

    def embed(self, views: list[torch.Tensor]) -> torch.Tensor:
        """The pooled views ``[B, N, *]`` (in :meth:`forward`'s order) -> ``[B, N, H]``; shared
        with the incremental form, which pools the views itself."""
        h = self.project(torch.cat(views, dim=-1))
        return h if self.node is None else h + self.node


class WindowBackbone(nn.Module):
    """Default backbone: window encoder per node, then message passing on the per-window node
    embeddings (not on every snapshot), then optional cross-node self-attention."""

    def __init__(
        self,
        in_features: int,
        num_nodes: int,
        window: int,
        hidden: int,
        dropout: float,
        graph_conv: GraphConvFactory | None = None,
        attention: bool = False,
        heads: int = 4,
        layers: int = 2,
        channels: int = 16,
        kernel: int = 5,
        convolutions: bool = False,
        statistics: bool = True,
        snapshot_mlp: bool = True,
        node_embedding: bool = True,
        first_record: bool = True,
    ) -> None:
        super().__init__()
        del window  # the encoder pools over time: any W works
        self.encoder = WindowEncoder(
            in_features,
            num_nodes,
            hidden,
            dropout,
            channels=channels,
            kernel=kernel,
            convolutions=convolutions,
            statistics=statistics,
            snapshot_mlp=snapshot_mlp,
            node_embedding=node_embedding,
            first_record=first_record,
        )
        self.convs = nn.ModuleList(
            [graph_conv(hidden=hidden, dropout=dropout, heads=heads) for _ in range(layers)]
            if graph_conv is not None
            else []
        )
        self.attention = _attention(hidden, heads, dropout) if attention else None

    def forward(
        self, x: torch.Tensor, adj: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        return self.message_passing(self.encoder(x), adj)

    def message_passing(
        self, skip: torch.Tensor, adj: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Per-window node embeddings ``[B, N, H]`` -> ``(refined, temporal, skip)``."""
        h = skip
        for conv in self.convs:
            h = conv(h, adj)
        refined = h if self.attention is None else self.attention(h)
        return refined, h, skip


class ThesisBackbone(nn.Module):
    """The thesis's backbone (§2.4.1): per snapshot, a linear embedding and two graph
    convolutions; a per-node GRU over the window; cross-node self-attention. Without a graph
    layer it is the thesis's ``mlp`` encoder: each node's flattened window through an MLP."""

    def __init__(
        self,
        in_features: int,
        num_nodes: int,
        window: int,
        hidden: int,
        dropout: float,
        graph_conv: GraphConvFactory | None = None,
        attention: bool = True,
        heads: int = 4,
    ) -> None:
        super().__init__()
        del num_nodes
        self.flat = None
        if graph_conv is None:
            self.flat = nn.Sequential(
                nn.Linear(window * in_features, hidden),
                nn.ReLU(),
                nn.Dropout(dropout),
                nn.Linear(hidden, hidden),
                nn.ReLU(),
            )
            return
        self.embed = nn.Linear(in_features, hidden)
        self.conv1 = graph_conv(hidden=hidden, dropout=dropout, heads=heads)
        self.conv2 = graph_conv(hidden=hidden, dropout=dropout, heads=heads)
        self.gru = nn.GRU(hidden, hidden, batch_first=True)
        self.attention = _attention(hidden, heads, dropout) if attention else None

    def forward(
        self, x: torch.Tensor, adj: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        b, w, n, f = x.shape
        if self.flat is not None:
            nodes = self.flat(x.permute(0, 2, 1, 3).reshape(b, n, w * f))
            return nodes, nodes, nodes
        c = self.embed.out_features
        flat = self.embed(x).reshape(b * w, n, c)
        adj_t = adj.unsqueeze(1).expand(b, w, n, n).reshape(b * w, n, n)
        first = self.conv1(flat, adj_t, w)
        second = self.conv2(first, adj_t, w)
        seq = second.reshape(b, w, n, c).transpose(1, 2).reshape(b * n, w, c)
        _, last = self.gru(seq)
        temporal = last[-1].reshape(b, n, c)
        refined = temporal if self.attention is None else self.attention(temporal)
        skip = first.reshape(b, w, n, c)[:, -1]
        return refined, temporal, skip
