"""The graph-model family of Table 3. One class whose switches add each variant's mechanism (pose
kernel, learned residual, spectral features, coupling head, graph attention, no cross-node path
at all); the config says which, so there is no registry. The spatio-temporal backbone is its own
config group (``backbone=window`` by default, ``backbone=thesis`` for the thesis's GCN + GRU).

Shapes: ``x [B, W, N, F]`` (J joints, then M sensors) -> ``class_logits [B, C]``,
``joint_logits [B, J]`` and, where present, ``recon_energy [B, J]``, ``gamma []``,
``severity [B]``.
"""

from __future__ import annotations

import torch
from torch import nn

from robohealth_mj import schema
from robohealth_mj.models.adjacency import AdjacencyBuilder
from robohealth_mj.models.backbone import GraphConvFactory, WindowBackbone
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
        backbone: GraphConvFactory | None = None,
        graph_conv: GraphConvFactory | None = None,
        attention: bool | None = None,
        max_pool: bool = True,
        pose_kernel: bool = False,
        learned_residual: bool = False,
        spectral_features: bool = False,
        anomaly_head: bool = False,
        anomaly_scores: str = "signed",
        severity_head: bool = False,
        pos_index: int = schema.feature_index("pos"),
    ) -> None:
        super().__init__()
        n = adjacency.shape[0]
        self.num_joints, self.pos_index = num_joints, pos_index
        self.adjacency = AdjacencyBuilder(adjacency, pose_kernel, learned_residual)
        self.spectral = SpectralFeatures(window) if spectral_features else None
        extra = NUM_SPECTRAL if spectral_features else 0
        make_backbone = backbone or WindowBackbone
        options = {} if attention is None else {"attention": attention}  # None: the backbone's
        self.backbone = make_backbone(
            in_features=in_features + extra,
            num_nodes=n,
            window=window,
            hidden=hidden,
            dropout=dropout,
            graph_conv=graph_conv,
            heads=heads,
            **options,
        )
        self.classifier = GraphClassifier(
            hidden,
            num_classes,
            dropout,
            pose_joints=num_joints if pose_kernel else 0,
            max_pool=max_pool,
        )
        self.anomaly = (
            AnomalyResidualHead(hidden, num_joints, n - num_joints, scores=anomaly_scores)
            if anomaly_head
            else None
        )
        self.localise = None if anomaly_head else NodeLocalisationHead(hidden, num_joints, dropout)
        self.severity = SeverityHead(hidden, dropout) if severity_head else None
        # added to the class logits; set by commissioning (runtime/operating_point.py)
        self.register_buffer("class_offset", torch.zeros(num_classes), persistent=False)

    def node_embeddings(self, x: torch.Tensor) -> torch.Tensor:
        """Refined per-node embeddings ``[B, N, H]`` (what the heads read)."""
        return self._features(x)[1][0]

    def _features(self, x: torch.Tensor):
        positions = x[:, -1, :, self.pos_index]  # [B, N], standardised
        adj = self.adjacency(positions)
        features = x
        if self.spectral is not None:
            spec = self.spectral(x).unsqueeze(1).expand(-1, x.shape[1], -1, -1)
            features = torch.cat([x, spec], dim=-1)
        return positions, self.backbone(features, adj)

    def forward(
        self, x: torch.Tensor, coupling: torch.Tensor | None = None
    ) -> dict[str, torch.Tensor]:
        """``coupling [B, J, M]``: each window's placement in place of the learned ``C``
        (training under drawn placements); coupling-head models only."""
        positions, (refined, temporal, skip) = self._features(x)
        return self.heads(positions, refined, temporal, skip, coupling)

    def heads(
        self,
        positions: torch.Tensor,
        refined: torch.Tensor,
        temporal: torch.Tensor,
        skip: torch.Tensor,
        coupling: torch.Tensor | None = None,
    ) -> dict[str, torch.Tensor]:
        """The output heads on the backbone's node embeddings (shared with the incremental
        form): positions ``[B, N]``, embeddings ``[B, N, H]`` -> the output dict."""
        logits = self.classifier(refined, positions[:, : self.num_joints]) + self.class_offset
        out = {"class_logits": logits}
        if self.anomaly is not None:
            out["joint_logits"], out["recon_energy"] = self.anomaly(temporal, coupling)
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
