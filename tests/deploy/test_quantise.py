"""int8 models: both forms quantised, run by the fleet runtime, deciding as the float model does
on nearly every tick; bad requests refused in one line."""

from __future__ import annotations

import base64
import subprocess
import sys

import numpy as np
import onnx
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.deploy.export import export_checkpoint
from robohealth_mj.deploy.quantise import first_products, quantise_model
from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime
from robohealth_mj.runtime.metadata import read_metadata

INTEGER_OPS = {"MatMulInteger", "DynamicQuantizeLinear", "QuantizeLinear", "QLinearMatMul"}


def _decisions(model, x: np.ndarray, streams: int = 4, ticks: int = 120) -> np.ndarray:
    """Class probabilities ``[ticks, streams, C]`` of a fleet replaying ``x`` (NaN undecided)."""
    fleet = FleetRuntime(model)
    assert fleet.mode == "incremental"
    slots = fleet.register([f"s{k}" for k in range(streams)])
    offsets = 150 * np.arange(streams)
    probs = np.full((ticks, streams, len(fleet.classes)), np.nan)
    for t in range(ticks):
        r = fleet.step(slots, np.full(streams, t), np.full(streams, 0.05 * (t + 1)), x[offsets + t])
        decided = r.status == DECIDED
        probs[t, decided] = r.probs[decided]
    return probs


@pytest.mark.parametrize("mode", ["dynamic", "static"])
def test_an_int8_model_runs_in_the_fleet_and_keeps_the_float_models_calls(deployed, tmp_path, mode):
    out = tmp_path / f"int8_{mode}.onnx"
    result = export_checkpoint(deployed["structural_ckpt"], out, quantise=mode)
    meta = read_metadata(out)
    assert meta["quantisation"] == mode and meta["model_id"].endswith(f"-int8{mode[0]}")
    assert meta["quantised_from"] == read_metadata(deployed["structural_onnx"])["model_id"]
    graphs = {"windowed": onnx.load(str(out))}
    for key in ("incremental_encode", "incremental_head"):  # the form the fleet runs
        graphs[key] = onnx.load_from_string(base64.b64decode(meta[key]))
    for name, proto in graphs.items():
        assert {n.op_type for n in proto.graph.node} & INTEGER_OPS, name
    # the first layers (inputs of mixed ranges) stay float products
    first = first_products(onnx.load(str(deployed["structural_onnx"])))
    kept = {n.name: n.op_type for n in graphs["windowed"].graph.node}
    assert first and all(kept.get(name) == "MatMul" for name in first)
    assert result["class_agreement"] >= 0.9
    rec = load_recordings([deployed["heldout"]])
    ref, got = _decisions(deployed["structural_onnx"], rec.x), _decisions(out, rec.x)
    decided = ~np.isnan(ref[..., 0])
    assert np.array_equal(decided, ~np.isnan(got[..., 0])) and decided.sum() > 300
    same = ref[decided].argmax(-1) == got[decided].argmax(-1)
    assert same.mean() >= 0.9
    assert np.abs(ref[decided] - got[decided]).max() < 0.5


def test_quantising_refuses_a_quantised_model_and_static_without_data(deployed, tmp_path):
    out = tmp_path / "int8.onnx"
    export_checkpoint(deployed["structural_ckpt"], out, quantise="dynamic")
    windows = np.zeros((2, 8, 12, 1), np.float32)
    with pytest.raises(InputError, match="already quantised"):
        quantise_model(out, tmp_path / "again.onnx", "dynamic", None, windows)
    with pytest.raises(InputError, match="quantise=static needs a calibration recording"):
        quantise_model(deployed["structural_onnx"], tmp_path / "s.onnx", "static", None, windows)
    assert not (tmp_path / "again.onnx").exists() and not (tmp_path / "s.onnx").exists()


def test_export_refuses_an_unknown_quantisation_in_one_line(tmp_path):
    args = [sys.executable, "-m", "robohealth_mj.export", f"ckpt={tmp_path}/none.ckpt",
            "quantise=int4"]  # fmt: skip
    proc = subprocess.run(args, capture_output=True, text=True, timeout=120)
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "quantise: 'int4' is not one of dynamic, static" in lines[0]
