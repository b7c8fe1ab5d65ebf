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
from robohealth_mj.common.errors import InputError
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
        coupled_edges: bool = False,
        anomaly_joint_scores: bool = False,
        coupling_fit: str = "losses",
        placement_embedding: bool = False,
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
            AnomalyResidualHead(
                hidden,
                num_joints,
                n - num_joints,
                scores=anomaly_scores,
                joint_scores=anomaly_joint_scores,
                coupling_fit=coupling_fit,
            )
            if anomaly_head
            else None
        )
        if (coupled_edges or anomaly_joint_scores or placement_embedding) and not anomaly_head:
            raise InputError(
                "model.coupled_edges, anomaly_joint_scores and placement_embedding need the "
                "coupling head (anomaly_head: true)"
            )
        if placement_embedding and not hasattr(self.backbone, "message_passing"):
            raise InputError("model.placement_embedding needs backbone=window")
        self.coupled_edges = coupled_edges
        # each sensor's embedding is told which joints it hears: its column of C
        self.placement = nn.Linear(num_joints, hidden, bias=False) if placement_embedding else None
        self.localise = None if anomaly_head else NodeLocalisationHead(hidden, num_joints, dropout)
        self.severity = SeverityHead(hidden, dropout) if severity_head else None
        # added to the class logits; set by commissioning (deploy/operating_point.py)
        self.register_buffer("class_offset", torch.zeros(num_classes), persistent=False)

    def node_embeddings(self, x: torch.Tensor) -> torch.Tensor:
        """Refined per-node embeddings ``[B, N, H]`` (what the heads read)."""
        return self._features(x)[1][0]

    def edges(self, positions: torch.Tensor, coupling: torch.Tensor | None = None) -> torch.Tensor:
        """Edge weights ``[B, N, N]`` the convolutions see. With ``coupled_edges`` the
        joint-sensor block is the placement (``coupling [B, J, M]`` when given, else the head's
        ``C``) instead of dense: message passing is told which sensors hear which joint, and a
        placement refitted by commissioning reaches it with the rest of the model frozen."""
        adj = self.adjacency(positions)
        if not self.coupled_edges:
            return adj
        j = self.num_joints
        block = adj[:, :j, j:]  # broadcast by a tensor op, not expand(b): ONNX keeps B dynamic
        c = self.anomaly.coupling() + torch.zeros_like(block) if coupling is None else coupling
        top = torch.cat([adj[:, :j, :j], c], dim=-1)
        bottom = torch.cat([c.transpose(1, 2), adj[:, j:, j:]], dim=-1)
        return torch.cat([top, bottom], dim=1)

    def placed(self, skip: torch.Tensor, coupling: torch.Tensor | None = None) -> torch.Tensor:
        """Encoder output ``skip [B, N, H]`` with each sensor told its placement: with
        ``placement_embedding``, a learned projection of its column of ``C`` (``coupling
        [B, J, M]`` when given, else the head's), normalised over joints, added to its
        embedding. A pool model's sensor nodes have no fixed meaning; this gives them one."""
        if self.placement is None:
            return skip
        j = self.num_joints
        c = self.anomaly.coupling() if coupling is None else coupling  # [J, M] or [B, J, M]
        heard = (c / c.sum(dim=-2, keepdim=True)).transpose(-1, -2)  # [(B,) M, J]
        return torch.cat([skip[:, :j], skip[:, j:] + self.placement(heard)], dim=1)

    def _features(self, x: torch.Tensor, coupling: torch.Tensor | None = None):
        positions = x[:, -1, :, self.pos_index]  # [B, N], standardised
        adj = self.edges(positions, coupling)
        features = x
        if self.spectral is not None:
            spec = self.spectral(x).unsqueeze(1).expand(-1, x.shape[1], -1, -1)
            features = torch.cat([x, spec], dim=-1)
        if self.placement is None:
            return positions, self.backbone(features, adj)
        skip = self.placed(self.backbone.encoder(features), coupling)
        return positions, self.backbone.message_passing(skip, adj)

    def forward(
        self, x: torch.Tensor, coupling: torch.Tensor | None = None
    ) -> dict[str, torch.Tensor]:
        """``coupling [B, J, M]``: each window's placement in place of the learned ``C``
        (training under drawn placements); coupling-head models only."""
        positions, (refined, temporal, skip) = self._features(x, coupling)
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
        return self.edges(positions)
