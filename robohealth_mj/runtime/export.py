"""Exporting a checkpoint to a self-contained ONNX model.

The model takes *raw* schema windows ``x: float32[B, W, 12, F]``: the graph transform (the
harness mixing, when the model was trained under it) and the normalisation are inside the graph,
so a deployment feeds sensor readings as they arrive. Metadata carries everything the runtime
checks: node order, feature names, window, label table, schema version, fingerprints.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np
import onnx
import torch
from torch import nn

from robohealth_mj import schema
from robohealth_mj.atomic import atomic_write_bytes
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.windows import make_windows
from robohealth_mj.learn.checkpoint import (
    check_schema,
    graph_from_checkpoint,
    load_checkpoint,
    model_from_checkpoint,
)
from robohealth_mj.learn.trainer import expand_paths
from robohealth_mj.models.onnx import export_onnx, onnx_parity

PARITY_TOLERANCE = 1e-4


class RawInput(nn.Module):
    """Schema window -> the model's graph (harness mixing) -> training-split z-scores."""

    def __init__(self, mean: torch.Tensor, std: torch.Tensor, coupling: np.ndarray | None) -> None:
        super().__init__()
        self.register_buffer("mean", mean.float().clone())
        self.register_buffer("std", std.float().clone())
        self.mix = coupling is not None
        if self.mix:
            self.register_buffer("coupling", torch.as_tensor(coupling, dtype=torch.float32))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        if self.mix:
            j = schema.N_JOINTS
            sensor = schema.SENSOR_CHANNELS
            mixed = torch.einsum("jm,bwjc->bwmc", self.coupling, x[..., j:, sensor])
            m = self.coupling.shape[1]
            head = torch.zeros(*x.shape[:2], m, sensor.start, dtype=x.dtype, device=x.device)
            head[..., 1] = 1.0  # is_sensor; joint-state channels stay zero
            x = torch.cat([x[..., :j, :], torch.cat([head, mixed], dim=-1)], dim=-2)
        return (x - self.mean) / self.std


def file_fingerprint(path: Path | str) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()[:16]


def heldout_windows(ckpt: dict[str, Any], data: str | list[str] | None, count: int) -> torch.Tensor:
    """Up to ``count`` raw windows ``[K, W, 12, F]`` spread over a held-out recording."""
    data = data or ckpt["config"].get("data", {}).get("evaluate", {}).get("heldout")
    if not data:
        raise ValueError("no held-out data for the parity check: pass data=PATH")
    files = expand_paths(data)
    for f in files:
        check_schema(ckpt, str(f))
    rec = load_recordings(files)
    windows = make_windows(rec, int(ckpt["window"]))
    pick = np.linspace(0, len(windows) - 1, min(count, len(windows))).astype(int)
    idx = windows.start[pick][:, None] + np.arange(windows.window)
    return torch.from_numpy(rec.x[idx])


def export_checkpoint(
    ckpt_path: Path | str,
    out: Path | str,
    data: str | list[str] | None = None,
    parity_windows: int = 256,
) -> dict[str, Any]:
    """Write ``out`` (ONNX) and verify it against PyTorch on real held-out windows."""
    ckpt = load_checkpoint(ckpt_path)
    model = model_from_checkpoint(ckpt)
    if callable(getattr(model, "fit", None)):
        raise ValueError(
            f"{ckpt_path}: variant {ckpt['variant']!r} is a tree ensemble, which has no ONNX "
            "export here; export a network variant"
        )
    graph = graph_from_checkpoint(ckpt)
    pre = RawInput(ckpt["norm_mean"], ckpt["norm_std"], graph.coupling).eval()
    windows = heldout_windows(ckpt, data, parity_windows)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp")
    outputs = export_onnx(model, windows[:2], tmp, pre=pre)
    error = onnx_parity(model, tmp, windows, pre=pre)
    side_data = tmp.with_name(tmp.name + ".data")  # the exporter's external weights, if any
    if not error <= PARITY_TOLERANCE:
        tmp.unlink(missing_ok=True)
        side_data.unlink(missing_ok=True)
        raise RuntimeError(
            f"ONNX parity check failed: max |torch - onnxruntime| / (1 + |torch|) = {error:.3g} "
            f"> {PARITY_TOLERANCE} on {len(windows)} held-out windows"
        )
    fingerprint = file_fingerprint(ckpt_path)
    metadata = model_metadata(
        model_id=f"{ckpt['variant']}-{graph.name}-w{ckpt['window']}-{fingerprint[:8]}",
        variant=ckpt["variant"],
        graph=graph.name,
        window=int(ckpt["window"]),
        outputs=outputs,
        classes=ckpt["labels"]["classes"],
        joints=ckpt["labels"]["joints"],
        checkpoint_fingerprint=fingerprint,
        data_fingerprint=ckpt["data_fingerprint"],
        code_version=ckpt["code_version"],
        parity_error=f"{error:.3g}",
    )
    attach_metadata(tmp, out, metadata)  # writes one self-contained file
    side_data.unlink(missing_ok=True)
    return {
        "path": str(out),
        "parity_error": error,
        "windows": len(windows),
        "metadata": metadata,
    }


def model_metadata(
    *,
    model_id: str,
    variant: str,
    graph: str,
    window: int,
    outputs: list[str],
    classes: list[str] | None = None,
    joints: list[str] | None = None,
    **extra: str,
) -> dict[str, str]:
    """The ONNX metadata the runtime checks and reports (all values are strings)."""
    return {
        "model_id": model_id,
        "variant": variant,
        "graph": graph,
        "schema_version": schema.SCHEMA_VERSION,
        "node_names": json.dumps(list(schema.NODE_NAMES)),
        "feature_names": json.dumps(list(schema.FEATURE_NAMES)),
        "edges": json.dumps([list(e) for e in schema.EDGES]),
        "window": str(window),
        "classes": json.dumps(classes or list(schema.FAULT_CLASSES)),
        "joints": json.dumps(joints or list(schema.JOINT_NAMES)),
        "outputs": json.dumps(outputs),
        **extra,
    }


def attach_metadata(src: Path | str, out: Path | str, metadata: dict[str, str]) -> None:
    """Write ``src`` with ``metadata`` to ``out`` atomically (``src`` removed if different)."""
    proto = onnx.load(str(src))
    onnx.helper.set_model_props(proto, metadata)
    atomic_write_bytes(out, proto.SerializeToString())
    if Path(src) != Path(out):
        Path(src).unlink()


def read_metadata(path: Path | str) -> dict[str, Any]:
    """The metadata an exported model carries, with JSON fields decoded."""
    proto = onnx.load(str(path), load_external_data=False)
    raw = {p.key: p.value for p in proto.metadata_props}
    decoded: dict[str, Any] = dict(raw)
    for key in ("node_names", "feature_names", "edges", "classes", "joints", "outputs"):
        if key in raw:
            decoded[key] = json.loads(raw[key])
    if "window" in raw:
        decoded["window"] = int(raw["window"])
    return decoded
