"""ONNX export of any variant with a dynamic batch size, and a parity check in onnxruntime.

The dynamo-based ``torch.onnx.export`` is used: the TorchScript tracer bakes the example batch
size into the reshapes of the spatio-temporal backbone and breaks parity at other batch sizes.
"""

from __future__ import annotations

import logging
import warnings
from pathlib import Path

import numpy as np
import torch
from torch import nn

OUTPUTS = ("class_logits", "joint_logits", "severity")


class ExportWrapper(nn.Module):
    """Tuple outputs for ONNX: class logits, joint logits (and severity when the head is on)."""

    def __init__(self, model: nn.Module, pre: nn.Module | None = None) -> None:
        super().__init__()
        self.model, self.pre = model, pre
        self.has_severity = getattr(model, "severity", None) is not None

    @property
    def output_names(self) -> list[str]:
        return list(OUTPUTS[: 3 if self.has_severity else 2])

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, ...]:
        if self.pre is not None:
            x = self.pre(x)
        out = self.model(x)
        return tuple(out[name] for name in self.output_names)


def export_onnx(
    model: nn.Module,
    example: torch.Tensor,
    path: Path | str,
    pre: nn.Module | None = None,
    opset: int = 18,
) -> list[str]:
    """Write ``path`` with input ``x: float32[batch, W, N, F]``; returns the output names."""
    wrapper = ExportWrapper(model, pre).eval()
    export_module(wrapper, (example,), path, ["x"], wrapper.output_names, opset)
    return wrapper.output_names


def export_module(
    module: nn.Module,
    examples: tuple[torch.Tensor, ...],
    path: Path | str,
    input_names: list[str],
    output_names: list[str],
    opset: int = 18,
) -> None:
    """Write ``path``: ``module`` on ``examples``, every input's first axis a dynamic batch."""
    batch = torch.export.Dim("batch", min=1, max=65536)
    for name in ("onnx_ir", "onnxscript", "torch.onnx"):  # their INFO lines are not ours to print
        logging.getLogger(name).setLevel(logging.WARNING)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        torch.onnx.export(
            module.eval(),
            examples,
            str(path),
            dynamo=True,
            opset_version=opset,
            input_names=input_names,
            output_names=output_names,
            dynamic_shapes=tuple({0: batch} for _ in examples),
            verbose=False,
        )


def onnx_parity(
    model: nn.Module, path: Path | str, inputs: torch.Tensor, pre: nn.Module | None = None
) -> float:
    """Largest difference between PyTorch and onnxruntime outputs on ``inputs``, relative to the
    output's size: ``max |torch - ort| / (1 + |torch|)``. Absolute for outputs below 1, relative
    above: float32 logits of magnitude ~20 differ by ~1e-4 from kernel order alone."""
    import onnxruntime as ort

    wrapper = ExportWrapper(model, pre).eval()
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    with torch.no_grad():
        reference = [t.numpy() for t in wrapper(inputs)]
    got = session.run(None, {"x": inputs.numpy()})
    return max(
        float((np.abs(r - g) / (1.0 + np.abs(r))).max())
        for r, g in zip(reference, got, strict=True)
    )
