"""The ST-GNN family: fixed, pose-gated, learned-residual and anomaly-residual variants share one
class whose switches add the mechanisms of Table 3 (no registry: the config says which)."""

from __future__ import annotations

import torch
from torch import nn

from robohealth_mj.models.adjacency import AdjacencyBuilder
from robohealth_mj.models.backbone import STBackbone
from robohealth_mj.models.heads import (
    AnomalyResidualHead,
    GraphClassifier,
    NodeLocalisationHead,
    SeverityHead,
)
from robohealth_mj.models.spectral import NUM_SPECTRAL, SpectralFeatures


class STGNN(nn.Module):
    """Spatio-temporal GNN on a dense ``[N, N]`` graph of J joints followed by M sensors."""

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
        pose_kernel: bool = False,
        learned_residual: bool = False,
        spectral_features: bool = False,
        anomaly_head: bool = False,
        severity_head: bool = False,
        pos_index: int = 2,
    ) -> None:
        super().__init__()
        n = adjacency.shape[0]
        self.num_joints, self.pos_index = num_joints, pos_index
        self.adjacency = AdjacencyBuilder(adjacency, pose_kernel, learned_residual)
        self.spectral = SpectralFeatures(window) if spectral_features else None
        extra = NUM_SPECTRAL if spectral_features else 0
        self.embed = nn.Linear(in_features + extra, hidden)
        self.backbone = STBackbone(hidden, dropout, heads)
        self.classifier = GraphClassifier(
            hidden, num_classes, dropout, pose_joints=num_joints if pose_kernel else 0
        )
        self.anomaly = (
            AnomalyResidualHead(hidden, num_joints, n - num_joints) if anomaly_head else None
        )
        self.localise = None if anomaly_head else NodeLocalisationHead(hidden, num_joints, dropout)
        self.severity = SeverityHead(hidden, dropout) if severity_head else None

    def forward(self, x: torch.Tensor) -> dict[str, torch.Tensor]:
        positions = x[:, -1, :, self.pos_index]  # [B, N], standardised
        adj = self.adjacency(positions)
        features = x
        if self.spectral is not None:
            spec = self.spectral(x).unsqueeze(1).expand(-1, x.shape[1], -1, -1)
            features = torch.cat([x, spec], dim=-1)
        refined, temporal, skip = self.backbone(self.embed(features), adj)
        out = {"class_logits": self.classifier(refined, positions[:, : self.num_joints])}
        if self.anomaly is not None:
            out["joint_logits"], out["recon_energy"] = self.anomaly(temporal)
        else:
            out["joint_logits"] = self.localise(refined, skip)
        gamma = self.adjacency.gamma()
        if gamma is not None:
            out["gamma"] = gamma
        if self.severity is not None:
            out["severity"] = self.severity(refined)
        return out

    def learned_adjacency(self, positions: torch.Tensor) -> torch.Tensor:
        """The edge weights the convolutions see for given standardised positions ``[B, N]``."""
        return self.adjacency(positions)
