"""``python -m robohealth_mj.render``: render a fault episode offscreen to GIF/MP4 (+ PNGs).

    python -m robohealth_mj.render model=model.onnx fault=jam joint=elbow severity=0.9 out=jam.gif
    python -m robohealth_mj.render fault=backlash joint=wrist_1 out=episode.mp4 png_dir=frames/

The simulator runs one fault from ``onset_s`` on; the runtime diagnoses the stream as it goes.
The overlay shows the true fault and the diagnosis; each joint housing is tinted by the model's
localisation score (no model: no tint, and the overlay says so).
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # before anything imports mujoco

from omegaconf import DictConfig

from robohealth_mj.common.config import run_tool
from robohealth_mj.common.errors import one_line_errors
from robohealth_mj.runtime.metadata import read_metadata

with one_line_errors("render"):  # a missing extra is one line, not a traceback
    from robohealth_mj.deploy.episode import render_episode


def main(argv: list[str] | None = None) -> None:
    run_tool("render", run, argv)


def run(cfg: DictConfig) -> None:
    with one_line_errors("render"):
        if cfg.model:
            read_metadata(cfg.model)  # a bad model file is the user's to fix, not a fallback
        frames = render_episode(cfg)
    print(
        f"rendered {len(frames)} frames ({cfg.width}x{cfg.height}, {cfg.fps} fps)"
        + (f" -> {cfg.out}" if cfg.out else "")
        + (f", PNGs in {cfg.png_dir}" if cfg.png_dir else "")
    )


if __name__ == "__main__":
    main()
