"""The ``gat`` baseline: multi-head graph attention (PyG ``DenseGATConv``) over the structural
mask instead of the spectral convolutions; no cross-node attention layer, no multi-scale skip."""

from __future__ import annotations

import torch
from torch import nn
from torch_geometric.nn import DenseGATConv

from robohealth_mj.models.heads import GraphClassifier, SeverityHead, mlp


class GATBlock(nn.Module):
    def __init__(self, hidden: int, heads: int, dropout: float) -> None:
        super().__init__()
        self.conv = DenseGATConv(hidden, hidden, heads=heads, concat=False, dropout=dropout)
        self.norm = nn.LayerNorm(hidden)
        self.dropout = nn.Dropout(dropout)

    def forward(self, h: torch.Tensor, adj: torch.Tensor) -> torch.Tensor:
        return h + self.dropout(torch.relu(self.norm(self.conv(h, adj))))


class GAT(nn.Module):
    def __init__(
        self,
        adjacency: torch.Tensor,
        num_joints: int,
        in_features: int,
        window: int,
        num_classes: int = 7,
        hidden: int = 64,
        dropout: float = 0.1,
        heads: int = 4,
        severity_head: bool = False,
    ) -> None:
        super().__init__()
        del window
        self.num_joints = num_joints
        self.register_buffer("mask", adjacency.float().clone())
        self.embed = nn.Linear(in_features, hidden)
        self.blocks = nn.ModuleList([GATBlock(hidden, heads, dropout) for _ in range(2)])
        self.gru = nn.GRU(hidden, hidden, batch_first=True)
        self.classifier = GraphClassifier(hidden, num_classes, dropout)
        self.localise = mlp(hidden, hidden, 1, dropout)
        self.severity = SeverityHead(hidden, dropout) if severity_head else None

    def forward(self, x: torch.Tensor) -> dict[str, torch.Tensor]:
        b, w, n, _ = x.shape
        h = self.embed(x).reshape(b * w, n, -1)
        for block in self.blocks:
            h = block(h, self.mask)
        seq = h.reshape(b, w, n, -1).transpose(1, 2).reshape(b * n, w, -1)
        _, last = self.gru(seq)
        nodes = last[-1].reshape(b, n, -1)
        out = {
            "class_logits": self.classifier(nodes),
            "joint_logits": self.localise(nodes[:, : self.num_joints]).squeeze(-1),
        }
        if self.severity is not None:
            out["severity"] = self.severity(nodes)
        return out
