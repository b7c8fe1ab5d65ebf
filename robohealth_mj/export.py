"""``python -m robohealth_mj.export ckpt=… [out=model.onnx] [data=heldout]``.

Writes an ONNX model taking raw windows (normalisation inside), with metadata, and fails loudly
if it differs from PyTorch by more than 1e-4 on real held-out windows.
"""

from __future__ import annotations

from pathlib import Path

import hydra
from omegaconf import DictConfig

from robohealth_mj.runtime.export import export_checkpoint


@hydra.main(config_path="../conf", config_name="export", version_base="1.3")
def main(cfg: DictConfig) -> None:
    if not cfg.ckpt:
        raise SystemExit("usage: python -m robohealth_mj.export ckpt=PATH [out=model.onnx]")
    out = cfg.out or Path(cfg.ckpt).with_name("model.onnx")
    result = export_checkpoint(cfg.ckpt, out, cfg.data, cfg.parity_windows)
    print(
        f"exported {result['metadata']['model_id']} -> {result['path']} "
        f"(parity {result['parity_error']:.2g} on {result['windows']} held-out windows)"
    )


if __name__ == "__main__":
    main()
