"""Edge weights of the dense graph: structural mask, pose kernel (Eq. 2), learned residual (Eq. 3).

Shapes: ``adjacency [N, N]`` (0/1 structural), positions ``[B, N]`` (standardised), output
``[B, N, N]``. Self-loops and symmetric normalisation are left to the graph convolution.
"""

from __future__ import annotations

import torch
from torch import nn


class PoseKernel(nn.Module):
    """``A'_ij = A_ij exp(-|gamma| (theta_i - theta_j)^2)``; gamma -> 0 recovers ``A``."""

    def __init__(self, init_gamma: float = 1.0) -> None:
        super().__init__()
        self.init_gamma = float(init_gamma)
        self.gamma = nn.Parameter(torch.tensor(self.init_gamma))
        self.reset_parameters()

    def reset_parameters(self) -> None:
        nn.init.constant_(self.gamma, self.init_gamma)

    def forward(self, adjacency: torch.Tensor, positions: torch.Tensor) -> torch.Tensor:
        diff = positions.unsqueeze(-1) - positions.unsqueeze(-2)  # [B, N, N]
        return adjacency * torch.exp(-self.gamma.abs() * diff.square())


class LearnedResidual(nn.Module):
    """``A'' = A' + (sigmoid(R) + sigmoid(R)^T) / 2`` with R initialised to -4 (sigmoid ~ 0.018),
    so the learned graph starts at the structural one and adds weight only where it helps."""

    def __init__(self, num_nodes: int, init: float = -4.0) -> None:
        super().__init__()
        self.init = float(init)
        self.logits = nn.Parameter(torch.empty(num_nodes, num_nodes))
        self.reset_parameters()

    def reset_parameters(self) -> None:
        nn.init.constant_(self.logits, self.init)

    def forward(self, adjacency: torch.Tensor) -> torch.Tensor:
        s = torch.sigmoid(self.logits)
        return adjacency + 0.5 * (s + s.transpose(0, 1))


class AdjacencyBuilder(nn.Module):
    """Per-sample edge weights from the structural graph and the optional mechanisms."""

    def __init__(self, adjacency: torch.Tensor, pose_kernel: bool, learned_residual: bool) -> None:
        super().__init__()
        self.register_buffer("structural", adjacency.float().clone())
        self.pose = PoseKernel() if pose_kernel else None
        self.residual = LearnedResidual(adjacency.shape[0]) if learned_residual else None

    def forward(self, positions: torch.Tensor) -> torch.Tensor:
        batch = positions.shape[0]
        adj = self.structural.unsqueeze(0).expand(batch, -1, -1)
        if self.pose is not None:
            adj = self.pose(adj, positions)
        if self.residual is not None:
            adj = self.residual(adj)
        return adj

    def gamma(self) -> torch.Tensor | None:
        return None if self.pose is None else self.pose.gamma.abs()
