"""Checkpoints: everything evaluation, export and the runtime need to rebuild the exact model.

Plain containers and tensors only, so ``torch.load(..., weights_only=True)`` reads them. Written
atomically (temp file + rename).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from robohealth_mj import schema
from robohealth_mj.atomic import atomic_write_bytes
from robohealth_mj.data.graphs import GraphSpec
from robohealth_mj.models import build_model

FORMAT = "robohealth_mj.checkpoint/1"


def save_checkpoint(
    path: Path | str,
    model: nn.Module,
    *,
    model_cfg: dict,
    variant: str,
    graph: GraphSpec,
    window: int,
    mean: np.ndarray,
    std: np.ndarray,
    config: dict,
    code_version: str,
    data_fingerprint: str,
    best_epoch: int,
    extra: dict[str, Any] | None = None,
) -> None:
    payload = {
        "format": FORMAT,
        "state_dict": {k: v.detach().cpu() for k, v in model.state_dict().items()},
        "model_cfg": model_cfg,
        "variant": variant,
        "schema": {
            "version": schema.SCHEMA_VERSION,
            "node_names": list(schema.NODE_NAMES),
            "edges": [list(e) for e in schema.EDGES],
            "feature_names": list(schema.FEATURE_NAMES),
        },
        "graph": graph.as_dict(),
        "window": int(window),
        "norm_mean": torch.from_numpy(np.asarray(mean, np.float32)),
        "norm_std": torch.from_numpy(np.asarray(std, np.float32)),
        "labels": {"classes": list(schema.FAULT_CLASSES), "joints": list(schema.JOINT_NAMES)},
        "config": config,
        "code_version": code_version,
        "data_fingerprint": data_fingerprint,
        "best_epoch": int(best_epoch),
        **(extra or {}),
    }
    buffer = io.BytesIO()
    torch.save(payload, buffer)
    atomic_write_bytes(path, buffer.getvalue())


def load_checkpoint(path: Path | str) -> dict[str, Any]:
    ckpt = torch.load(str(path), map_location="cpu", weights_only=True)
    if not isinstance(ckpt, dict) or ckpt.get("format") != FORMAT:
        raise ValueError(f"{path}: not a robohealth_mj checkpoint ({FORMAT})")
    return ckpt


def graph_from_checkpoint(ckpt: dict[str, Any]) -> GraphSpec:
    g = ckpt["graph"]
    coupling = None if g["coupling"] is None else np.asarray(g["coupling"], np.float32)
    return GraphSpec(
        g["name"],
        tuple(g["node_names"]),
        np.asarray(g["adjacency"], np.float32),
        int(g["num_joints"]),
        coupling,
    )


def model_from_checkpoint(ckpt: dict[str, Any]) -> nn.Module:
    graph = graph_from_checkpoint(ckpt)
    model = build_model(
        ckpt["model_cfg"],
        graph.adjacency,
        graph.num_joints,
        len(ckpt["schema"]["feature_names"]),
        ckpt["window"],
    )
    model.load_state_dict(ckpt["state_dict"])
    return model.eval()


def check_schema(ckpt: dict[str, Any], source: str) -> None:
    """Refuse data whose node order or topology differs from what the model was trained on."""
    s = ckpt["schema"]
    if s["node_names"] != list(schema.NODE_NAMES):
        raise ValueError(
            f"{source}: node order {list(schema.NODE_NAMES)} differs from the "
            f"checkpoint's {s['node_names']}"
        )
    if s["edges"] != [list(e) for e in schema.EDGES]:
        raise ValueError(f"{source}: graph topology differs from the checkpoint's")
    if s["version"] != schema.SCHEMA_VERSION:
        raise ValueError(f"{source}: schema {schema.SCHEMA_VERSION} != checkpoint's {s['version']}")
