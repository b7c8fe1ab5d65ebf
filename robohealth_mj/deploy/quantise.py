"""int8 forms of an exported model, through onnxruntime's quantisation tools.

Both of the model's forms are quantised alike: the windowed graph (the file's own) and the
incremental form's two graphs in its metadata, which the fleet runtime runs. Only the matrix
products (``MatMul``, ``Gemm``) are quantised; the raw-input normalisation, the window statistics,
layer norms and activations stay float, since a few heavy-tailed channels (jam impulses) would
spend an 8-bit activation range on their tails.

- ``dynamic``: int8 weights; each product's activations are quantised per call from their own
  range. Needs no data.
- ``static``: int8 weights and activations, with ranges fixed from a calibration recording run
  through the float model (a training session: never the held-out one).

A quantised model no longer matches PyTorch to the export's 1e-4; what it keeps is measured
(:func:`agreement`) and written into its metadata.
"""

from __future__ import annotations

import base64
import logging
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import onnx

from robohealth_mj import schema
from robohealth_mj.common.atomic import atomic_write_bytes
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.numeric import softmax

MODES = ("dynamic", "static")
QUANTISED_OPS = ["MatMul", "Gemm"]
CALIBRATION_STREAMS = 16  # streams the calibration recording is replayed on (offset apart)
CALIBRATION_BATCHES = 64  # feeds kept per graph


class _Recorder:
    """Stands in for an onnxruntime session: runs the real one and keeps what it was fed."""

    def __init__(self, session: Any) -> None:
        self.session, self.feeds = session, []

    def run(self, names, feeds):
        self.feeds.append({k: np.array(v, copy=True) for k, v in feeds.items()})
        return self.session.run(names, feeds)

    def get_inputs(self):
        return self.session.get_inputs()


class _Feeds:
    """onnxruntime's calibration reader over a list of recorded feeds."""

    def __init__(self, feeds: list[dict[str, np.ndarray]]) -> None:
        self._it: Iterator[dict[str, np.ndarray]] = iter(feeds)

    def get_next(self) -> dict[str, np.ndarray] | None:
        return next(self._it, None)


def _every(feeds: list, count: int) -> list:
    """``count`` feeds spread over the list (all when fewer)."""
    if len(feeds) <= count:
        return feeds
    return [feeds[int(i)] for i in np.linspace(0, len(feeds) - 1, count)]


def calibration_feeds(
    model: bytes, meta: dict[str, str], frames: np.ndarray
) -> dict[str, list[dict[str, np.ndarray]]]:
    """What each graph is fed while the float model runs over ``frames [T, N, F]`` (raw
    snapshots): the windowed graph's windows, and the incremental form's encode and head inputs
    as the fleet runtime makes them, on streams replaying the recording from spread offsets."""
    import onnxruntime as ort

    from robohealth_mj.runtime.incremental import IncrementalEngine

    window = int(meta["window"])
    if len(frames) < 2 * window:
        raise InputError(f"calibration: {len(frames)} snapshots, fewer than two windows")
    starts = np.arange(0, len(frames) - window + 1, window)
    windows = np.stack([frames[s : s + window] for s in starts]).astype(np.float32)
    feeds: dict[str, list[dict[str, np.ndarray]]] = {
        "windowed": [{"x": windows[i : i + 32]} for i in range(0, len(windows), 32)]
    }
    if "incremental_encode" in meta:

        def session(blob: bytes):
            return ort.InferenceSession(blob, providers=["CPUExecutionProvider"])

        encode = _Recorder(session(base64.b64decode(meta["incremental_encode"])))
        head = _Recorder(session(base64.b64decode(meta["incremental_head"])))
        streams = CALIBRATION_STREAMS
        engine = IncrementalEngine(
            encode, head, window, int(meta["incremental_nodes"]), schema.N_FEATURES,
            int(meta["incremental_channels"]), int(meta["first_signal"]), capacity=streams,
        )  # fmt: skip
        slots = np.arange(streams, dtype=np.int64)
        offsets = np.linspace(0, len(frames), streams, endpoint=False).astype(np.int64)
        for t in range(min(len(frames), 8 * window)):
            engine.push(slots, frames[(offsets + t) % len(frames)].astype(np.float32))
            if engine.full(slots).all():
                engine.infer(slots)
        feeds["encode"], feeds["head"] = encode.feeds, head.feeds
    return {k: _every(v, CALIBRATION_BATCHES) for k, v in feeds.items()}


def first_products(proto: onnx.ModelProto) -> list[str]:
    """The matrix products that read the graph's inputs through no other product: the first
    layers, whose inputs mix node-type flags, normalised channels and window statistics of very
    different ranges, which one 8-bit scale per tensor cannot hold (measured: quantised, they
    changed a quarter of a trained model's calls)."""
    producer = {out: node for node in proto.graph.node for out in node.output}
    inputs = {i.name for i in proto.graph.input}

    def reaches_input(name: str, seen: set[str]) -> bool:
        if name in inputs:
            return True
        node = producer.get(name)
        if node is None or node.name in seen or node.op_type in QUANTISED_OPS:
            return False
        seen.add(node.name)
        return any(reaches_input(i, seen) for i in node.input)

    return [
        n.name for n in proto.graph.node
        if n.op_type in QUANTISED_OPS and reaches_input(n.input[0], set())
    ]  # fmt: skip


def quantise_graph(
    model: bytes, mode: str, feeds: list[dict[str, np.ndarray]] | None = None
) -> bytes:
    """One ONNX graph's int8 form (``mode`` in :data:`MODES`); its first layers stay float."""
    from onnxruntime.quantization import (
        CalibrationMethod,
        QuantFormat,
        QuantType,
        quantize_dynamic,
        quantize_static,
    )

    quiet = logging.getLogger()  # the tools log every tensor at INFO, and Hydra listens at INFO
    level = quiet.level
    quiet.setLevel(logging.ERROR)
    with tempfile.TemporaryDirectory() as tmp:
        src, out = Path(tmp, "float.onnx"), Path(tmp, "int8.onnx")
        proto = onnx.load_from_string(model)
        del proto.metadata_props[:]  # the caller writes the metadata once, on the whole file
        onnx.save(proto, str(src))
        first = first_products(proto)
        if mode == "dynamic":
            quantize_dynamic(
                src, out, weight_type=QuantType.QInt8, op_types_to_quantize=QUANTISED_OPS,
                nodes_to_exclude=first,
            )  # fmt: skip
        else:
            quantize_static(
                src, out, _Feeds(feeds or []), quant_format=QuantFormat.QDQ,
                op_types_to_quantize=QUANTISED_OPS, activation_type=QuantType.QUInt8,
                weight_type=QuantType.QInt8, calibrate_method=CalibrationMethod.MinMax,
                nodes_to_exclude=first, per_channel=True,
            )  # fmt: skip
        quantised = onnx.load(str(out)).SerializeToString()
    quiet.setLevel(level)
    return quantised


def agreement(float_model: bytes, int8_model: bytes, windows: np.ndarray) -> dict[str, float]:
    """How far the int8 windowed graph is from the float one on ``windows [B, W, N, F]``: the
    share of windows with the same class and (on windows either calls faulted) the same joint,
    and the largest class-probability difference."""
    import onnxruntime as ort

    def outputs(model: bytes) -> list[np.ndarray]:
        session = ort.InferenceSession(model, providers=["CPUExecutionProvider"])
        return session.run(None, {"x": windows.astype(np.float32)})

    ref, got = outputs(float_model), outputs(int8_model)
    cls_ref, cls_got = ref[0].argmax(-1), got[0].argmax(-1)
    faulted = (cls_ref > 0) | (cls_got > 0)
    same_joint = ref[1].argmax(-1) == got[1].argmax(-1)
    return {
        "class_agreement": float((cls_ref == cls_got).mean()),
        "joint_agreement": float(same_joint[faulted].mean()) if faulted.any() else 1.0,
        "max_probability_difference": float(np.abs(softmax(ref[0]) - softmax(got[0])).max()),
    }


def quantise_model(
    src: Path | str, out: Path | str, mode: str, calibration: np.ndarray | None,
    check: np.ndarray,
) -> dict[str, Any]:  # fmt: skip
    """Write the int8 form of the exported model ``src`` to ``out`` (atomically): both forms
    quantised, ``static`` calibrated on ``calibration [T, N, F]`` raw snapshots; its agreement
    with the float model on ``check [B, W, N, F]`` windows goes into the metadata."""
    if mode not in MODES:
        raise InputError(f"quantise: {mode!r} is not one of {', '.join(MODES)}")
    if mode == "static" and calibration is None:
        raise InputError("quantise=static needs a calibration recording (calibration=PATH)")
    proto = onnx.load(str(src))
    meta = {p.key: p.value for p in proto.metadata_props}
    if "quantisation" in meta:
        raise InputError(f"{src}: already quantised ({meta['quantisation']})")
    whole = proto.SerializeToString()
    feeds = calibration_feeds(whole, meta, calibration) if mode == "static" else {}
    windowed = quantise_graph(whole, mode, feeds.get("windowed"))
    for name in ("encode", "head"):
        key = f"incremental_{name}"
        if key in meta:
            blob = quantise_graph(base64.b64decode(meta[key]), mode, feeds.get(name))
            meta[key] = base64.b64encode(blob).decode("ascii")
    agreed = agreement(whole, windowed, check)
    meta.update(
        model_id=f"{meta['model_id']}-int8{mode[0]}",
        quantisation=mode,
        quantised_from=meta["model_id"],
        **{f"quantisation_{k}": f"{v:.4g}" for k, v in agreed.items()},
    )
    quantised = onnx.load_from_string(windowed)
    onnx.helper.set_model_props(quantised, meta)
    atomic_write_bytes(out, quantised.SerializeToString())
    return {"path": str(out), "metadata": meta, **agreed}
