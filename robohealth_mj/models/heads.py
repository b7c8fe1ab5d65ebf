"""Output heads: graph classifier, per-node localisation, anomaly-residual localisation (Eq. 1),
and the optional severity regressor."""

from __future__ import annotations

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from robohealth_mj.common.errors import InputError

COUPLING_FLOOR = 1e-2  # a set C's smallest entry: softplus never reaches zero


def mlp(in_dim: int, hidden: int, out_dim: int, dropout: float = 0.0) -> nn.Sequential:
    return nn.Sequential(
        nn.Linear(in_dim, hidden), nn.ReLU(), nn.Dropout(dropout), nn.Linear(hidden, out_dim)
    )


class GraphClassifier(nn.Module):
    """Mean-pooled (and, with ``max_pool``, max-pooled) node embeddings, + an MLP of the last
    joint positions for pose variants. The max keeps one sensor's strong evidence from being
    averaged away over twelve nodes."""

    def __init__(
        self,
        hidden: int,
        num_classes: int,
        dropout: float,
        pose_joints: int = 0,
        max_pool: bool = False,
    ) -> None:
        super().__init__()
        self.max_pool = max_pool
        self.pose = mlp(pose_joints, hidden, hidden) if pose_joints else None
        width = hidden * (1 + int(max_pool) + int(bool(pose_joints)))
        self.out = mlp(width, hidden, num_classes, dropout)

    def forward(
        self, nodes: torch.Tensor, joint_positions: torch.Tensor | None = None
    ) -> torch.Tensor:
        pooled = nodes.mean(dim=1)
        if self.max_pool:
            pooled = torch.cat([pooled, nodes.amax(dim=1)], dim=-1)
        if self.pose is not None:
            pooled = torch.cat([pooled, self.pose(joint_positions)], dim=-1)
        return self.out(pooled)


class NodeLocalisationHead(nn.Module):
    """Per-node score from refined embeddings + the first-convolution skip; joints only, so a
    sensor node can never win the localisation argmax."""

    def __init__(self, hidden: int, num_joints: int, dropout: float) -> None:
        super().__init__()
        self.num_joints = num_joints
        self.score = mlp(2 * hidden, hidden, 1, dropout)

    def forward(self, refined: torch.Tensor, skip: torch.Tensor) -> torch.Tensor:
        joints = slice(0, self.num_joints)
        return self.score(torch.cat([refined[:, joints], skip[:, joints]], dim=-1)).squeeze(-1)


class AnomalyResidualHead(nn.Module):
    """Learned joint-sensor coupling ``C = softplus(C_logits) in R>=0^{J x M}`` (thesis Eq. 1).

    ``C_pred`` (columns sum to 1 over joints) predicts each sensor embedding from its coupled
    joints; the residual ``r_m = s_m - f(sum_j C_pred_jm h_j)`` is scored by ``g`` and scattered
    back through ``C_scat`` (rows sum to 1 over sensors) to joint logits, and ``||r_m||^2 / H`` to
    a per-joint reconstruction energy for the healthy-data penalty. Works for any M.

    ``scores="signed"`` (the thesis) lets ``g`` score a sensor anything, so a model may localise
    with an *inverted* C: the anomalous sensor scored low and the joint coupled to it *least*
    winning. ``scores="energy"`` scores ``||W r_m||^2 / H``: zero for a sensor predicted exactly,
    growing with its residual, so the joint that wins is the one coupled most to the sensors
    that deviate, which pins C's sign *given* the embeddings; but the residual is a learned
    embedding, so a network can still make the faulted sensor's residual small and the others'
    large and learn an inverted C (it did, at a reconstruction weight of 1.0).

    ``coupling_fit="motion"`` pins the sign by construction: ``C`` is not trained. Training
    sets it once, before the first step, to the motion estimate of the placement on the
    training data's healthy running (:mod:`robohealth_mj.learn.motion_placement`, the
    estimator commissioning uses): each entry a non-negative least-squares weight of how much
    of a joint's motion-predicted emission a sensor carries. It stays frozen, so no loss can
    move it, and with energy scores (``>= 0``) a sensor's deviation can only raise the logits of
    the joints it carries. ``coupling_fit="given"``: the graph's true placement, set and frozen
    the same way; a study's ceiling (the same sensors with the placement known), not something a
    user has. ``coupling_fit="losses"`` (the thesis): every loss trains ``C``.

    ``joint_scores`` adds a per-joint score ``v(h_j)`` from each joint's own embedding. Told a
    placement (a pool model), the scattered scores alone are a fixed function of the sensors'
    scores, so two joints coupled to the same sensors alike always tie; ``v`` can break the tie
    with the joint's own motion and what message passing brought it.
    """

    SCORES = ("signed", "energy")
    FITS = ("losses", "motion", "given")

    def __init__(
        self,
        hidden: int,
        num_joints: int,
        num_sensors: int,
        init_noise: float = 0.01,
        scores: str = "signed",
        joint_scores: bool = False,
        coupling_fit: str = "losses",
    ) -> None:
        super().__init__()
        if scores not in self.SCORES:
            raise InputError(f"model.anomaly_scores must be one of {self.SCORES}, got {scores!r}")
        if coupling_fit not in self.FITS:
            raise InputError(f"model.coupling_fit must be one of {self.FITS}, got {coupling_fit!r}")
        self.coupling_fit = coupling_fit
        self.num_joints, self.num_sensors = num_joints, num_sensors
        self.init_noise = float(init_noise)
        # frozen under the motion fit: set once before training, never a loss's to move
        self.coupling_logits = nn.Parameter(
            torch.empty(num_joints, num_sensors), requires_grad=coupling_fit == "losses"
        )
        self.f = mlp(hidden, hidden, hidden)
        self.scores = scores
        self.g = mlp(hidden, hidden, 1) if scores == "signed" else nn.Linear(hidden, hidden, False)
        self.v = mlp(hidden, hidden, 1) if joint_scores else None
        self.reset_parameters()

    def reset_parameters(self) -> None:
        nn.init.normal_(self.coupling_logits, 0.0, self.init_noise)  # near-uniform, no prior

    def coupling(self) -> torch.Tensor:
        return F.softplus(self.coupling_logits)

    @torch.no_grad()
    def set_coupling(self, c: torch.Tensor | np.ndarray, floor: float = COUPLING_FLOOR) -> None:
        """Set ``C`` to a given placement ``[J, M]`` (entries below ``floor`` are raised to it,
        since softplus never reaches zero): a placement known, or a start for refitting."""
        c = torch.as_tensor(np.asarray(c), dtype=torch.float32).clamp_min(floor)
        self.coupling_logits.copy_(torch.log(torch.expm1(c)))

    def normalisations(
        self, coupling: torch.Tensor | None = None
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """``(C_pred, C_scat)``: ``C`` (the learned one, or ``coupling`` ``[..., J, M]``) with
        columns and rows summing to 1."""
        c = self.coupling() if coupling is None else coupling
        return c / c.sum(dim=-2, keepdim=True), c / c.sum(dim=-1, keepdim=True)

    def forward(
        self, nodes: torch.Tensor, coupling: torch.Tensor | None = None
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """``nodes [B, N, H]`` -> joint logits and reconstruction energy ``[B, J]``; with
        ``coupling [B, J, M]`` (each window's placement, given in training under drawn
        placements) in place of the learned ``C``."""
        h = nodes[:, : self.num_joints]  # [B, J, H]
        s = nodes[:, self.num_joints :]  # [B, M, H]
        c_pred, c_scat = self.normalisations(coupling)
        per_window = "b" if coupling is not None else ""  # one C for all, or one per window
        predicted = self.f(torch.einsum(f"{per_window}jm,bjh->bmh", c_pred, h))
        residual = s - predicted
        if self.scores == "signed":
            scores = self.g(residual).squeeze(-1)  # [B, M], any sign
        else:
            scores = self.g(residual).square().mean(-1)  # [B, M], >= 0, grows with |r_m|
        logits = torch.einsum(f"bm,{per_window}jm->bj", scores, c_scat)  # [B, J]
        if self.v is not None:
            logits = logits + self.v(h).squeeze(-1)
        energy = torch.einsum(f"bm,{per_window}jm->bj", residual.square().mean(-1), c_scat)
        return logits, energy

    def reconstruction_error(self, nodes: torch.Tensor) -> torch.Tensor:
        """Each sensor's prediction error from its coupled joints, unweighted by ``C_scat``
        ``[B, M]``: what refitting ``C`` on healthy running minimises (a weighted energy could
        be lowered by scattering every sensor onto the joints predicted best)."""
        c_pred, _ = self.normalisations()
        predicted = self.f(torch.einsum("jm,bjh->bmh", c_pred, nodes[:, : self.num_joints]))
        return (nodes[:, self.num_joints :] - predicted).square().mean(-1)


class SeverityHead(nn.Module):
    """Per-window severity in [0, 1] from the pooled embedding (thesis §4.7 extension)."""

    def __init__(self, hidden: int, dropout: float) -> None:
        super().__init__()
        self.out = mlp(hidden, hidden, 1, dropout)

    def forward(self, nodes: torch.Tensor) -> torch.Tensor:
        return torch.sigmoid(self.out(nodes.mean(dim=1))).squeeze(-1)
