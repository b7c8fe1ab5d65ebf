"""Training under drawn placements: a coupling-head model that can later be recalibrated to a
placement nobody measured (commissioning, :mod:`robohealth_mj.deploy.commission`).

A model trained on one harness placement learns that placement into everything it has (the
sensor nodes' embeddings, the predictor ``f``), so refitting ``C`` alone on another placement
finds nothing (``studies/stock_arm/results/recouple_trial.txt``). Here every training window is
mixed by a
placement drawn from a pool (``random_coupling`` with the graph's number of sensors) and the
model is *given* that placement in place of its learned ``C``; what it learns is how to use any
placement. The sensors of every placement are z-scored on the healthy training snapshots, the
statistics commissioning can refit from an arm's healthy running alone.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.graphs import GraphSpec, random_coupling
from robohealth_mj.data.windows import covered
from robohealth_mj.models.heads import COUPLING_FLOOR

POOL_SEED = 10_000  # pool placements come from seeds POOL_SEED + k: apart from campaign seeds


def mixed_statistics(
    coupling: np.ndarray, mean: np.ndarray, cov: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Mean and std ``[M, C]`` of the sensors ``sum_j C[j, m] p_j`` from the packages' per-channel
    mean ``[J, C]`` and covariance across joints ``[C, J, J]``: exact, since mixing is linear."""
    mu = np.einsum("jm,jc->mc", coupling, mean)
    var = np.einsum("jm,cjk,km->mc", coupling, cov, coupling)
    std = np.sqrt(np.maximum(var, 0.0))
    std[std < 1e-6] = 1.0
    return mu.astype(np.float32), std.astype(np.float32)


def healthy_sensor_statistics(graph: GraphSpec, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and std ``[M, C]`` of ``graph``'s sensor channels over schema snapshots ``x``
    ``[T, 2J, F]`` (healthy running): the sensor rows of a placement's normalisation."""
    mixed = graph.transform(x)[:, graph.num_joints :, schema.SENSOR_CHANNELS].astype(np.float64)
    std = mixed.std(axis=0)
    std[std < 1e-6] = 1.0
    return mixed.mean(axis=0).astype(np.float32), std.astype(np.float32)


class PlacementPool:
    """``size`` placements of the graph's ``M`` sensors, and the packages they mix.

    ``x`` is the recording's snapshots ``[T, 2J, F]`` after the sensing profile's mask;
    ``healthy`` marks the snapshots (training windows, no active fault) whose statistics
    z-score each placement's sensors.
    """

    def __init__(
        self,
        graph: GraphSpec,
        x: np.ndarray,
        healthy: np.ndarray,
        size: int,
        device: torch.device,
        noise: float = 0.0,
    ) -> None:
        if graph.coupling is None:
            raise InputError("trainer.placements needs graph=harness (a placement to draw)")
        if size < 2:
            raise InputError(f"trainer.placements: a pool of at least 2 placements, got {size}")
        if not 0.0 <= noise < 2.0:
            raise InputError(f"trainer.placement_noise must be in [0, 2), got {noise}")
        self.noise = float(noise)
        j, m = graph.coupling.shape
        couplings = np.stack([random_coupling(POOL_SEED + k, m, j) for k in range(size)])
        packages = x[:, j:, schema.SENSOR_CHANNELS].astype(np.float64)
        ok = packages[healthy]
        self.package_mean = ok.mean(axis=0)  # [J, C]
        centred = ok - self.package_mean
        self.package_cov = np.einsum("tjc,tkc->cjk", centred, centred) / max(len(ok) - 1, 1)
        stats = [self.statistics(c) for c in couplings]
        self.device = device
        self.couplings = torch.from_numpy(couplings).to(device)  # [K, J, M]
        self.mean = torch.from_numpy(np.stack([s[0] for s in stats])).to(device)  # [K, M, C]
        self.std = torch.from_numpy(np.stack([s[1] for s in stats])).to(device)
        self.packages = torch.from_numpy(packages.astype(np.float32)).to(device)  # [T, J, C]
        self.num_joints = j

    def statistics(self, coupling: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Healthy mean and std ``[M, C]`` of the sensors a placement ``[J, M]`` mixes."""
        return mixed_statistics(coupling, self.package_mean, self.package_cov)

    def mix(
        self, x: torch.Tensor, snapshots: torch.Tensor, generator: torch.Generator
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Each window ``x [B, W, N, F]`` (its snapshot indices ``[B, W]``) with its sensors
        re-mixed by a placement drawn from the pool -> ``(x, couplings [B, J, M])``."""
        k = torch.randint(0, len(self.couplings), (len(x),), generator=generator).to(self.device)
        c = self.couplings[k]
        mixed = torch.einsum("bjm,bwjc->bwmc", c, self.packages[snapshots])
        mixed = (mixed - self.mean[k][:, None]) / self.std[k][:, None]
        out = x.clone()
        out[:, :, self.num_joints :, schema.SENSOR_CHANNELS] = mixed
        return out, self.as_found(c, generator) if self.noise else c

    def as_found(self, c: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        """Placements ``c [B, J, M]`` as a fit from healthy running finds them: every entry's
        scale off by ``exp(s N(0, 1))``, a joint's weaker sensor missed and a sensor it does
        not reach found, each with probability ``s / 2``; raised to the floor a commissioned
        ``C`` has (softplus never reaches zero), which also keeps a sensor whose only joint was
        missed in the normalisations. The data stay mixed by ``c``."""
        s = self.noise
        scale, coin, value = (
            draw(c.shape, generator=generator).to(c.device)
            for draw in (torch.randn, torch.rand, torch.rand)
        )
        reached = c > 0
        weaker = reached & (c < c.amax(dim=2, keepdim=True))
        found = torch.where(reached, c * torch.exp(s * scale), s * value)
        keep = torch.where(reached, ~(weaker & (coin < s / 2)), coin < s / 2)
        return (found * keep).clamp_min(COUPLING_FLOOR)


def placement_pool(
    graph: GraphSpec, rec, train: Any, size: int, device, noise: float = 0.0
) -> PlacementPool:
    """The pool of drawn placements and the packages they mix (the profile's channels), with
    the healthy training snapshots that z-score them."""
    x = rec.x if graph.channel_mask is None else rec.x * graph.channel_mask
    healthy = covered(train, len(rec)) & ~rec.active
    return PlacementPool(graph, x, healthy, size, device, noise)


def given_placement(model, graph: GraphSpec, pool: PlacementPool, mean, std) -> None:
    """A model trained under drawn placements is given its graph's own placement (its ``C``
    is set, not learned: validation and the checkpoint use it), and that placement's sensors
    are z-scored on the healthy statistics the pool uses for every other placement."""
    head = getattr(model, "anomaly", None)
    if head is None:
        raise InputError("trainer.placements needs a coupling-head variant (anomaly_residual)")
    head.set_coupling(graph.coupling)
    head.coupling_logits.requires_grad_(False)
    j = graph.num_joints
    mu, sd = pool.statistics(np.asarray(graph.coupling))
    mean[j:, schema.SENSOR_CHANNELS], std[j:, schema.SENSOR_CHANNELS] = mu, sd
