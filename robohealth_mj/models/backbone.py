"""The shared spatio-temporal backbone (thesis §2.4.1).

Per snapshot: two dense graph convolutions (PyG ``DenseGCNConv``: self-loops, symmetric
normalisation) on the per-sample edge weights, each followed by LayerNorm, ReLU, dropout and a
residual skip; then a per-node GRU over the window and one cross-node Transformer self-attention
layer, so each node can compare itself with its peers.

Shapes: ``h [B, W, N, H]``, ``adj [B, N, N]`` -> refined ``[B, N, H]``, temporal ``[B, N, H]``,
first-conv skip ``[B, N, H]`` (last snapshot).
"""

from __future__ import annotations

import torch
from torch import nn
from torch_geometric.nn import DenseGCNConv


class TimeSharedDropout(nn.Module):
    """Dropout with one mask per (window, node, channel), shared across the window's snapshots
    (variational dropout): the same regularisation for the temporal model, at 1/W of the cost of
    drawing a fresh mask for every snapshot."""

    def __init__(self, p: float) -> None:
        super().__init__()
        self.p = float(p)

    def forward(self, h: torch.Tensor, window: int) -> torch.Tensor:
        if not self.training or self.p == 0.0:
            return h
        bw, n, c = h.shape
        keep = torch.rand(bw // window, 1, n, c, device=h.device) >= self.p
        mask = keep.to(h.dtype).div_(1.0 - self.p)
        return (h.reshape(-1, window, n, c) * mask).reshape(bw, n, c)


class GraphConvBlock(nn.Module):
    def __init__(self, hidden: int, dropout: float) -> None:
        super().__init__()
        self.conv = DenseGCNConv(hidden, hidden)
        self.norm = nn.LayerNorm(hidden)
        self.dropout = TimeSharedDropout(dropout)

    def forward(self, h: torch.Tensor, adj: torch.Tensor, window: int) -> torch.Tensor:
        return h + self.dropout(torch.relu(self.norm(self.conv(h, adj))), window)


class STBackbone(nn.Module):
    def __init__(self, hidden: int, dropout: float, heads: int) -> None:
        super().__init__()
        self.conv1 = GraphConvBlock(hidden, dropout)
        self.conv2 = GraphConvBlock(hidden, dropout)
        self.gru = nn.GRU(hidden, hidden, batch_first=True)
        self.attention = nn.TransformerEncoderLayer(
            hidden, heads, dim_feedforward=2 * hidden, dropout=dropout, batch_first=True
        )

    def forward(
        self, h: torch.Tensor, adj: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        b, w, n, c = h.shape
        flat = h.reshape(b * w, n, c)
        adj_t = adj.unsqueeze(1).expand(b, w, n, n).reshape(b * w, n, n)
        first = self.conv1(flat, adj_t, w)
        second = self.conv2(first, adj_t, w)
        seq = second.reshape(b, w, n, c).transpose(1, 2).reshape(b * n, w, c)
        _, last = self.gru(seq)
        temporal = last[-1].reshape(b, n, c)
        refined = self.attention(temporal)
        skip = first.reshape(b, w, n, c)[:, -1]
        return refined, temporal, skip
