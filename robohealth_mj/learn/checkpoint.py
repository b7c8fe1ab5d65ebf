"""Checkpoints: everything evaluation, export and the runtime need to rebuild the exact model.

Plain containers and tensors only, so ``torch.load(..., weights_only=True)`` reads them. Written
atomically (temp file + rename).
"""

from __future__ import annotations

import hashlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from robohealth_mj import schema
from robohealth_mj.common.atomic import atomic_write_bytes
from robohealth_mj.common.errors import InputError
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
            "node_names": list(graph.arm.nodes),
            "edges": [list(e) for e in graph.arm.edges],
            "feature_names": list(schema.FEATURE_NAMES),
        },
        "graph": graph.as_dict(),
        "window": int(window),
        "norm_mean": torch.from_numpy(np.asarray(mean, np.float32)),
        "norm_std": torch.from_numpy(np.asarray(std, np.float32)),
        "labels": {"classes": list(schema.FAULT_CLASSES), "joints": list(graph.arm.joints)},
        "config": config,
        "code_version": code_version,
        "data_fingerprint": data_fingerprint,
        "best_epoch": int(best_epoch),
        **(extra or {}),
    }
    write_checkpoint(path, payload)


def write_checkpoint(path: Path | str, payload: dict[str, Any]) -> None:
    """``payload`` with its checksum, written atomically."""
    payload["sha256"] = checkpoint_digest(payload)
    buffer = io.BytesIO()
    torch.save(payload, buffer)
    atomic_write_bytes(path, buffer.getvalue())


def checkpoint_digest(payload: dict[str, Any]) -> str:
    """SHA-256 over the weights, the normalisation and every other field: torch's archive does
    not check its own contents, so altered bytes inside a tensor would otherwise load."""
    digest = hashlib.sha256()
    for key in sorted(payload["state_dict"]):
        digest.update(key.encode())
        digest.update(payload["state_dict"][key].contiguous().numpy().tobytes())
    for key in ("norm_mean", "norm_std"):
        digest.update(payload[key].numpy().tobytes())
    rest = {
        k: v
        for k, v in payload.items()
        if k not in ("state_dict", "norm_mean", "norm_std", "sha256")
    }
    digest.update(json.dumps(rest, sort_keys=True, default=str).encode())
    return digest.hexdigest()


_REQUIRED = ("state_dict", "model_cfg", "variant", "schema", "graph", "window", "norm_mean",
             "norm_std", "labels", "config", "data_fingerprint")  # fmt: skip


def load_checkpoint(path: Path | str) -> dict[str, Any]:
    """A checkpoint, or an :class:`InputError` naming the file and what is wrong with it (empty,
    truncated or altered bytes, another format, a missing key or checksum, another schema or
    topology)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no checkpoint file")
    if path.stat().st_size == 0:
        raise InputError(f"{path}: empty file, not a checkpoint")
    try:
        ckpt = torch.load(str(path), map_location="cpu", weights_only=True)
    except Exception as exc:  # torch raises many types for damaged archives
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InputError(
            f"{path}: unreadable checkpoint, truncated or altered? ({type(exc).__name__}: "
            f"{first[:160]})"
        ) from None
    if not isinstance(ckpt, dict) or ckpt.get("format") != FORMAT:
        raise InputError(f"{path}: not a robohealth_mj checkpoint ({FORMAT})")
    missing = [k for k in _REQUIRED if k not in ckpt]
    if missing:
        raise InputError(f"{path}: key '{missing[0]}' missing from the checkpoint")
    if "sha256" not in ckpt:  # a deleted checksum would otherwise let altered bytes load
        raise InputError(
            f"{path}: key 'sha256' missing: the checkpoint's checksum was removed, so its "
            "contents cannot be trusted; re-save it with this version (train or export)"
        )
    if checkpoint_digest(ckpt) != ckpt["sha256"]:
        raise InputError(
            f"{path}: checksum mismatch: the checkpoint was altered after it was written"
        )
    try:
        check_schema(ckpt, f"{path} (checkpoint)")
    except (KeyError, TypeError) as exc:
        raise InputError(f"{path}: key 'schema' malformed ({exc})") from None
    return ckpt


def graph_from_checkpoint(ckpt: dict[str, Any]) -> GraphSpec:
    g = ckpt["graph"]
    coupling = None if g["coupling"] is None else np.asarray(g["coupling"], np.float32)
    mask = g.get("channel_mask")  # absent before sensing profiles: every channel
    return GraphSpec(
        g["name"],
        tuple(g["node_names"]),
        np.asarray(g["adjacency"], np.float32),
        int(g["num_joints"]),
        coupling,
        g.get("sensing", "full"),
        None if mask is None else np.asarray(mask, np.float32),
        int(g.get("schema_nodes", schema.N_NODES)),  # absent before the stock profile: all
        tuple(g.get("classes", schema.FAULT_CLASSES)),
        None if g.get("baseline_shift") is None else np.asarray(g["baseline_shift"], np.float32),
        checkpoint_arm(ckpt),
        g.get("coupling_seed"),
    )


def checkpoint_arm(ckpt: dict[str, Any]) -> schema.ArmGraph:
    """The arm graph a checkpoint was trained on (the UR's before schema 3.0)."""
    return schema.ArmGraph.of_nodes(ckpt["schema"]["node_names"])


def joint_score_kind(ckpt: dict[str, Any]) -> str:
    """How the runtime turns joint logits into scores, as the model was trained: ``softmax``
    over the joints (the default loss: one joint at fault, the joints compete) or ``sigmoid``
    per joint (the thesis's BCE). Softmax-trained logits are not sigmoid-calibrated: on a
    confident window every joint's logit is large, and sigmoid scores all saturate at 1."""
    trainer = (ckpt.get("config") or {}).get("trainer") or {}
    return "softmax" if trainer.get("joint_softmax", True) else "sigmoid"


def model_from_checkpoint(ckpt: dict[str, Any]) -> nn.Module:
    graph = graph_from_checkpoint(ckpt)
    model = build_model(
        ckpt["model_cfg"],
        graph.adjacency,
        graph.num_joints,
        len(ckpt["schema"]["feature_names"]),
        ckpt["window"],
    )
    try:
        model.load_state_dict(ckpt["state_dict"])
    except RuntimeError as exc:
        first = str(exc).splitlines()[0]
        raise InputError(f"checkpoint key 'state_dict' does not fit its model: {first}") from None
    if ckpt.get("class_offset") is not None:  # a commissioned healthy operating point
        model.class_offset.copy_(torch.as_tensor(ckpt["class_offset"], dtype=torch.float32))
    return model.eval()


def training_arms(files: list) -> list[str]:
    """The arms the recordings ``files`` say they come from (those that say), sorted."""
    from robohealth_mj.data.read import recording_arm

    return sorted({a for a in map(recording_arm, files) if a is not None})


def check_recordings(ckpt: dict[str, Any], files: list) -> None:
    """Refuse, in one line, a recording of another schema, one lacking channels the model reads
    (its sensing profile's: a full model on a controller log, say), or one of an arm the model was
    not trained on, unless it was trained for transfer (``transfer=true``, several arms): then
    any arm whose description ships reads, its channels relative to its own ratings."""
    from robohealth_mj.arms.description import load_arm
    from robohealth_mj.data.read import recording_arm, recording_sensing
    from robohealth_mj.data.sensing import refuse_missing_channels

    sensing = graph_from_checkpoint(ckpt).sensing
    arms = list(ckpt.get("arms") or [])  # empty: trained on recordings that name no arm
    for f in files:
        check_schema(ckpt, str(f))
        refuse_missing_channels(sensing, recording_sensing(f), str(f))
        arm = recording_arm(f)
        if not arms or arm is None or arm in arms:
            continue
        if ckpt.get("transfer"):
            load_arm(arm)  # its description must be readable: the ratings scale its channels
            continue
        raise InputError(
            f"{f}: a recording of a {arm}; the model was trained on {', '.join(arms)} and "
            f"reads no other arm (train one on {arm} recordings, or one with transfer=true on "
            "several arms)"
        )


def load_checked(ckpt: dict[str, Any], files: list, arm: str | None = None):
    """``files`` as a Recording the model reads (:func:`check_recordings`, then loaded), or one
    line where they are of another arm graph than the model's."""
    from robohealth_mj.data.arrays import load_recordings

    check_recordings(ckpt, files)
    rec = load_recordings(files, arm, pad=bool(ckpt.get("transfer")))
    check_schema(ckpt, str(files[0]), rec.graph)
    return rec


def check_schema(ckpt: dict[str, Any], source: str, graph: schema.ArmGraph | None = None) -> None:
    """Refuse a checkpoint of a schema this code does not read, one whose graph is not an arm's,
    and data (``graph``: the recordings') whose node order or topology differs from what the
    model was trained on."""
    s = ckpt["schema"]
    if s["version"] not in schema.READABLE_VERSIONS:
        raise InputError(
            f"{source}: schema {s['version']} is not one this code reads "
            f"({', '.join(schema.READABLE_VERSIONS)})"
        )
    try:
        trained = checkpoint_arm(ckpt)
    except ValueError as exc:
        raise InputError(f"{source}: key 'schema.node_names': {exc}") from None
    if s["edges"] != [list(e) for e in trained.edges]:
        raise InputError(f"{source}: graph topology differs from the checkpoint's arm graph")
    if graph is not None and not trained.reads(graph):
        raise InputError(
            f"{source}: an arm of joints {list(graph.joints)}; the model was trained on "
            f"{list(trained.joints)}"
        )
