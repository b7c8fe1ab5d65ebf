"""Exporting a checkpoint to a self-contained ONNX model.

The model takes *raw* windows ``x: float32[B, W, 2J, F]`` of one arm (on its graph: 12 nodes on
a UR): that arm's channel scale (:mod:`robohealth_mj.data.relative`), the graph transform (the
harness mixing, when the model was trained under it) and the normalisation are inside the graph,
so a deployment feeds sensor readings as they arrive. Metadata carries everything the runtime
checks: node order, feature names, window, label table, schema version, fingerprints, the arm it
reads and its graph.
"""

from __future__ import annotations

import base64
import hashlib
import json
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import onnx
import torch
from torch import nn

from robohealth_mj import schema
from robohealth_mj.common.atomic import atomic_write_bytes
from robohealth_mj.data.arrays import Recording, expand_paths, single_arm
from robohealth_mj.data.baseline import shift
from robohealth_mj.data.relative import channel_scale, to_raw
from robohealth_mj.data.windows import make_windows
from robohealth_mj.learn.checkpoint import (
    graph_from_checkpoint,
    joint_score_kind,
    load_checked,
    load_checkpoint,
    model_from_checkpoint,
)
from robohealth_mj.models.incremental import PooledHead, SnapshotStep, supports_incremental
from robohealth_mj.models.onnx import ExportWrapper, export_module, export_onnx, onnx_parity
from robohealth_mj.runtime.contact import Placing
from robohealth_mj.runtime.metadata import read_metadata  # noqa: F401 (re-exported)
from robohealth_mj.sim.contact_surface import arm_surface

PARITY_TOLERANCE = 1e-4


class RawInput(nn.Module):
    """Schema window of the arm's raw readings -> relative channels -> the commissioned arm's
    residuals onto the training arms' baseline -> the sensing profile's channels and nodes -> the
    model's graph (harness mixing) -> training-split z-scores."""

    def __init__(
        self,
        mean: torch.Tensor,
        std: torch.Tensor,
        coupling: np.ndarray | None,
        channel_mask: np.ndarray | None = None,
        schema_nodes: int = schema.N_NODES,
        baseline_shift: np.ndarray | None = None,
        channel_scale: np.ndarray | None = None,
        arm_nodes: int = schema.N_NODES,
    ) -> None:
        """``arm_nodes``: the arm graph's nodes (2 J), what a raw window carries."""
        super().__init__()
        self.schema_nodes, self.arm_nodes = schema_nodes, arm_nodes
        self.scaled = channel_scale is not None and not np.all(channel_scale == 1.0)
        if self.scaled:
            self.register_buffer("channel_scale", torch.tensor(np.array(channel_scale)).float())
        self.shifted = baseline_shift is not None
        if self.shifted:
            self.register_buffer("baseline_shift", torch.as_tensor(baseline_shift).float())
        self.register_buffer("mean", mean.float().clone())
        self.register_buffer("std", std.float().clone())
        self.masked = channel_mask is not None
        if self.masked:
            self.register_buffer("channel_mask", torch.as_tensor(channel_mask, dtype=torch.float32))
        self.mix = coupling is not None
        if self.mix:
            self.register_buffer("coupling", torch.as_tensor(coupling, dtype=torch.float32))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        if self.scaled:
            x = x * self.channel_scale
        if self.shifted:
            x = shift(x, self.baseline_shift)
        if self.masked:
            x = x * self.channel_mask
        if self.schema_nodes < self.arm_nodes:
            x = x[..., : self.schema_nodes, :]
        if self.mix:
            j = self.arm_nodes // 2
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


def heldout_recording(
    ckpt: dict[str, Any], data: str | list[str] | None, arm: str | None = None
) -> tuple[Recording, str]:
    """The held-out data the parity checks run on (``data`` or the checkpoint's own) and the
    arm it comes from, which the exported model reads (``arm``: for data that names none)."""
    data = data or ckpt["config"].get("data", {}).get("evaluate", {}).get("heldout")
    if not data:
        raise ValueError("no held-out data for the parity check: pass data=PATH")
    files = expand_paths(data)
    return load_checked(ckpt, files, arm), single_arm(files, arm)


def calibration_frames(ckpt: dict[str, Any], data: str | list[str] | None, arm: str) -> np.ndarray:
    """Raw snapshots ``[T, 2J, F]`` that static quantisation fixes its ranges on: ``data`` or
    the checkpoint's first training session (never held-out data)."""
    files = expand_paths(data) if data else expand_paths(ckpt["config"]["data"]["train"])[:1]
    return to_raw(load_checked(ckpt, files, arm).x, arm)


def heldout_windows(rec: Recording, window: int, count: int, arm: str) -> torch.Tensor:
    """Up to ``count`` raw windows ``[K, W, 2J, F]`` (arm ``arm``'s readings) spread over a
    held-out recording."""
    windows = make_windows(rec, window)
    pick = np.linspace(0, len(windows) - 1, min(count, len(windows))).astype(int)
    idx = windows.start[pick][:, None] + np.arange(windows.window)
    return torch.from_numpy(to_raw(rec.x[idx], arm))


def heldout_run(rec: Recording, count: int, arm: str) -> torch.Tensor:
    """The first ``count`` consecutive raw snapshots ``[count, 2J, F]`` of one held-out run."""
    step = np.diff(rec.sample_index, prepend=rec.sample_index[0] - 1)
    same = (rec.run == rec.run[0]) & (step == 1)
    length = int(np.argmin(same)) if not same.all() else len(rec)
    if length < count:
        raise ValueError(f"held-out data has no run of {count} consecutive samples")
    return torch.from_numpy(to_raw(rec.x[:count], arm))


def incremental_graphs(
    model: nn.Module, pre: nn.Module, run: torch.Tensor, window: int
) -> dict[str, str]:
    """The incremental form's two graphs (base64 ONNX, for the metadata) after checking it
    against the windowed model on every window of ``run`` (``[T, 2J, F]`` consecutive)."""
    import onnxruntime as ort

    from robohealth_mj.runtime.incremental import IncrementalEngine

    step, head = SnapshotStep(model, pre).eval(), PooledHead(model).eval()
    with torch.no_grad():
        z = pre(run[:2, None])[:, 0]
        z, g = step(run[:2], z, torch.ones(2))
    n, f, channels = z.shape[1], z.shape[2], g.shape[2]
    signals = f - model.backbone.encoder.first_signal
    examples = (torch.zeros(2, n, 3 * channels + 7 * signals + f - signals), z)
    blobs = {}
    with tempfile.TemporaryDirectory() as tmp:
        first = (z.clone() + 1.0,) if step.first_record else ()  # distinct: aliases merge
        export_module(
            step,
            (run[:2], z, torch.ones(2), *first),
            f"{tmp}/encode.onnx",
            step.input_names,
            step.output_names,
        )
        export_module(
            head,
            examples,
            f"{tmp}/head.onnx",
            ["views", "z_last"],
            head.output_names,
        )
        for name in ("encode", "head"):
            proto = onnx.load(f"{tmp}/{name}.onnx")  # external weights folded in
            blobs[name] = proto.SerializeToString()
    engine = IncrementalEngine(
        ort.InferenceSession(blobs["encode"], providers=["CPUExecutionProvider"]),
        ort.InferenceSession(blobs["head"], providers=["CPUExecutionProvider"]),
        window,
        n,
        f,
        channels,
        model.backbone.encoder.first_signal,
        capacity=1,
    )
    slot = np.zeros(1, dtype=np.int64)
    got, starts = [], []
    for t in range(len(run)):
        engine.push(slot, run[t : t + 1].numpy())
        if engine.full(slot)[0]:
            got.append(engine.infer(slot))
            starts.append(t - window + 1)
    idx = torch.as_tensor(starts)[:, None] + torch.arange(window)
    with torch.no_grad():
        reference = [o.numpy() for o in ExportWrapper(model, pre).eval()(run[idx])]
    error = max(
        float((np.abs(r - np.concatenate([o[k] for o in got])) / (1.0 + np.abs(r))).max())
        for k, r in enumerate(reference)
    )
    if not error <= PARITY_TOLERANCE:
        raise RuntimeError(
            f"incremental form differs from the windowed model: {error:.3g} > {PARITY_TOLERANCE} "
            f"on {len(starts)} consecutive windows"
        )
    return {
        "incremental_encode": base64.b64encode(blobs["encode"]).decode("ascii"),
        "incremental_head": base64.b64encode(blobs["head"]).decode("ascii"),
        "incremental_parity_error": f"{error:.3g}",
        "incremental_channels": str(channels),
        "incremental_nodes": str(n),
        "first_signal": str(model.backbone.encoder.first_signal),
    }


def export_checkpoint(
    ckpt_path: Path | str,
    out: Path | str,
    data: str | list[str] | None = None,
    parity_windows: int = 256,
    arm: str | None = None,
    quantise: str | None = None,
    calibration: str | list[str] | None = None,
) -> dict[str, Any]:
    """Write ``out`` (ONNX) for the arm ``data`` comes from (``arm`` where it names none) and
    verify it against PyTorch on real held-out windows of it; with ``quantise`` (``dynamic``,
    ``static``), its int8 form instead, calibrated on ``calibration`` (default: the
    checkpoint's first training session) and measured against the float form on those
    held-out windows."""
    ckpt = load_checkpoint(ckpt_path)
    model = model_from_checkpoint(ckpt)
    if callable(getattr(model, "fit", None)):
        raise ValueError(
            f"{ckpt_path}: variant {ckpt['variant']!r} is a tree ensemble, which has no ONNX "
            "export here; export a network variant"
        )
    graph = graph_from_checkpoint(ckpt)
    rec, target = heldout_recording(ckpt, data, arm)
    pre = RawInput(
        ckpt["norm_mean"],
        ckpt["norm_std"],
        graph.coupling,
        graph.channel_mask,
        graph.schema_nodes,
        graph.baseline_shift,
        channel_scale(target),
        graph.arm.n_nodes,
    ).eval()
    window = int(ckpt["window"])
    windows = heldout_windows(rec, window, parity_windows, target)
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
    incremental = (
        incremental_graphs(model, pre, heldout_run(rec, 2 * window + 64, target), window)
        if supports_incremental(model)
        else {}
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
        joint_scores=joint_score_kind(ckpt),
        sensing=graph.sensing,
        label_set=json.dumps(list(graph.classes)),
        arms=json.dumps(list(ckpt.get("arms") or [])),
        arm=target,
        arm_graph=graph.arm,
        transfer=json.dumps(bool(ckpt.get("transfer"))),
        **commissioning_metadata(ckpt),
        **incremental,
    )
    if quantise:
        from robohealth_mj.deploy.quantise import quantise_model

        float_path = out.with_name(f".{out.name}.float.tmp")
        attach_metadata(tmp, float_path, metadata)
        side_data.unlink(missing_ok=True)
        frames = calibration_frames(ckpt, calibration, target) if quantise == "static" else None
        try:
            result = quantise_model(float_path, out, quantise, frames, windows.numpy())
        finally:
            float_path.unlink(missing_ok=True)
        return {**result, "parity_error": error, "windows": len(windows)}
    attach_metadata(tmp, out, metadata)  # writes one self-contained file
    side_data.unlink(missing_ok=True)
    return {
        "path": str(out),
        "parity_error": error,
        "windows": len(windows),
        "metadata": metadata,
    }


def commissioning_metadata(ckpt: dict[str, Any]) -> dict[str, str]:
    """What a commissioned model was commissioned on (nothing for one that was not), and the
    contact watch's thresholds and what places a contact on a link, where commissioning fitted
    them."""
    record = ckpt.get("commissioning")
    if not record:
        return {}
    contact = record.get("contact") or {}
    threshold, quiet = contact.get("threshold_nm"), contact.get("quiet_nm")
    placing = {}
    if threshold and quiet and record.get("arm"):  # commissioned before 2026-11-27: no quiet_nm
        surface = Placing(arm_surface(record["arm"]), np.asarray(quiet))
        placing = {"contact_placing": json.dumps(surface.to_dict())}
    return {
        "commissioning_data_fingerprint": record["healthy_fingerprint"],
        "commissioning_healthy_minutes": str(record["healthy_minutes"]),
        **({"contact_threshold_nm": json.dumps(threshold)} if threshold else {}),
        **placing,
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
    arm_graph: schema.ArmGraph = schema.UR_GRAPH,
    **extra: str,
) -> dict[str, str]:
    """The ONNX metadata the runtime checks and reports (all values are strings): the arm graph
    a raw window must be on (``node_names``, ``edges``) among them."""
    return {
        "model_id": model_id,
        "variant": variant,
        "graph": graph,
        "schema_version": schema.SCHEMA_VERSION,
        "node_names": json.dumps(list(arm_graph.nodes)),
        "feature_names": json.dumps(list(schema.FEATURE_NAMES)),
        "edges": json.dumps([list(e) for e in arm_graph.edges]),
        "window": str(window),
        "classes": json.dumps(classes or list(schema.FAULT_CLASSES)),
        "joints": json.dumps(joints or list(arm_graph.joints)),
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
