"""``python -m robohealth_mj.export ckpt=… [out=model.onnx] [data=heldout] [quantise=static]``.

Writes an ONNX model taking raw windows (normalisation inside), with metadata, and fails loudly
if it differs from PyTorch by more than 1e-4 on real held-out windows.
"""

from __future__ import annotations

from pathlib import Path

from omegaconf import DictConfig

from robohealth_mj.common.config import arm_choice, run_tool
from robohealth_mj.common.errors import InputError, one_line_errors

with one_line_errors("export"):  # a missing extra is one line, not a traceback
    from robohealth_mj.deploy.export import export_checkpoint


def main(argv: list[str] | None = None) -> None:
    run_tool("export", run, argv)


def run(cfg: DictConfig) -> None:
    if not cfg.ckpt:
        raise SystemExit("usage: python -m robohealth_mj.export ckpt=PATH [out=model.onnx]")
    out = cfg.out or Path(cfg.ckpt).with_name("model.onnx")
    with one_line_errors("export"):
        if cfg.quantise not in (None, "dynamic", "static"):
            raise InputError(f"quantise: {cfg.quantise!r} is not one of dynamic, static (or null)")
        result = export_checkpoint(
            cfg.ckpt, out, cfg.data, cfg.parity_windows, arm_choice(cfg), cfg.quantise,
            cfg.calibration,
        )  # fmt: skip
    if cfg.quantise:
        print(
            f"exported {result['metadata']['model_id']} ({cfg.quantise} int8) -> {result['path']} "
            f"(float parity {result['parity_error']:.2g}; against the float model on "
            f"{result['windows']} held-out windows: class agreement {result['class_agreement']:.3f}"
            f", joint {result['joint_agreement']:.3f}, largest probability difference "
            f"{result['max_probability_difference']:.3f})"
        )
        return
    incremental = result["metadata"].get("incremental_parity_error")
    print(
        f"exported {result['metadata']['model_id']} for the {result['metadata']['arm']} -> "
        f"{result['path']} "
        f"(parity {result['parity_error']:.2g} on {result['windows']} held-out windows"
        + (f"; incremental form parity {incremental}" if incremental else "; windowed only")
        + ")"
    )


if __name__ == "__main__":
    main()
