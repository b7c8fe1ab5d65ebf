"""Instantiating a model variant from its config and the graph it runs on."""

from __future__ import annotations

import numpy as np
import torch
from hydra.utils import instantiate
from omegaconf import DictConfig, OmegaConf
from torch import nn

from robohealth_mj.common.errors import InputError


def build_model(
    model_cfg: DictConfig | dict,
    adjacency: np.ndarray | torch.Tensor,
    num_joints: int,
    in_features: int,
    window: int,
    **overrides,
) -> nn.Module:
    """``conf/variant/<name>.yaml`` + the graph (``[N, N]`` adjacency, J joints first) -> module."""
    adjacency = torch.as_tensor(np.asarray(adjacency), dtype=torch.float32)
    if adjacency.ndim != 2 or adjacency.shape[0] != adjacency.shape[1]:
        raise ValueError(f"adjacency must be square [N, N], got {tuple(adjacency.shape)}")
    if not 0 < num_joints <= adjacency.shape[0]:
        raise ValueError(f"num_joints={num_joints} must be in 1..{adjacency.shape[0]} (the nodes)")
    cfg = (
        OmegaConf.to_container(model_cfg, resolve=True)
        if isinstance(model_cfg, DictConfig)
        else dict(model_cfg)
    )
    cfg.pop("name", None)  # the variant's name, for records; not a constructor argument
    if cfg.get("anomaly_head") and num_joints == adjacency.shape[0]:
        raise InputError(
            "the coupling head learns which sensors each joint reaches, and this graph has no "
            "sensor nodes (sensing=stock): choose a variant without it, e.g. stgnn_fixed"
        )
    return instantiate(
        cfg,
        adjacency=adjacency,
        num_joints=num_joints,
        in_features=in_features,
        window=window,
        **overrides,
    )
