"""The ``mlp`` baseline: each node's flattened window is encoded on its own, with no cross-node
pathway at all (the control whose localisation must collapse to chance)."""

from __future__ import annotations

import torch
from torch import nn

from robohealth_mj.models.heads import GraphClassifier, SeverityHead, mlp


class NodeMLP(nn.Module):
    def __init__(
        self,
        adjacency: torch.Tensor,
        num_joints: int,
        in_features: int,
        window: int,
        num_classes: int = 7,
        hidden: int = 64,
        dropout: float = 0.1,
        severity_head: bool = False,
    ) -> None:
        super().__init__()
        del adjacency  # no graph: that is the point of this baseline
        self.num_joints = num_joints
        self.encoder = nn.Sequential(mlp(window * in_features, hidden, hidden, dropout), nn.ReLU())
        self.classifier = GraphClassifier(hidden, num_classes, dropout)
        self.localise = mlp(hidden, hidden, 1, dropout)
        self.severity = SeverityHead(hidden, dropout) if severity_head else None

    def node_embeddings(self, x: torch.Tensor) -> torch.Tensor:
        b, w, n, f = x.shape
        return self.encoder(x.permute(0, 2, 1, 3).reshape(b, n, w * f))

    def forward(self, x: torch.Tensor) -> dict[str, torch.Tensor]:
        nodes = self.node_embeddings(x)
        out = {
            "class_logits": self.classifier(nodes),
            "joint_logits": self.localise(nodes[:, : self.num_joints]).squeeze(-1),
        }
        if self.severity is not None:
            out["severity"] = self.severity(nodes)
        return out
