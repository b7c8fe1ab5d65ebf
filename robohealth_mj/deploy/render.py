"""Offscreen rendering of a fault episode: the arm moving, the true fault and the model's
diagnosis as an overlay, and every joint housing tinted by its localisation score.

MuJoCo renders headless through EGL by default (``MUJOCO_GL=egl``); on a machine without a GPU,
Mesa's EGL renders on the CPU. Set ``MUJOCO_GL`` before importing this module to choose.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
from PIL import Image, ImageDraw

HEALTHY_RGBA = np.array([0.49, 0.678, 0.8, 1.0])
FAULT_RGBA = np.array([0.95, 0.15, 0.1, 1.0])


class JointTint:
    """Colours each joint's housing from UR blue (score 0) to red (score 1)."""

    def __init__(self, model: mujoco.MjModel) -> None:
        self.model = model
        joints = [model.actuator(k).name for k in range(model.nu)]  # one servo per joint
        self.geoms = [model.geom(f"{j}_housing").id for j in joints]
        model.geom_matid[self.geoms] = -1  # let geom_rgba decide the colour

    def apply(self, scores: Sequence[float] | None) -> None:
        scores = np.zeros(len(self.geoms)) if scores is None else np.clip(scores, 0.0, 1.0)
        for geom, s in zip(self.geoms, scores, strict=True):
            self.model.geom_rgba[geom] = HEALTHY_RGBA + (FAULT_RGBA - HEALTHY_RGBA) * s


@dataclass
class Frame:
    image: np.ndarray  # [H, W, 3] uint8
    t: float


def draw_overlay(
    image: np.ndarray, lines: Sequence[tuple[str, tuple[int, int, int]]]
) -> np.ndarray:
    canvas = Image.fromarray(image)
    draw = ImageDraw.Draw(canvas)
    height = 14 * len(lines) + 8
    draw.rectangle([0, 0, canvas.width, height], fill=(0, 0, 0))
    for k, (text, colour) in enumerate(lines):
        draw.text((6, 4 + 14 * k), text, fill=colour)
    return np.asarray(canvas)


class EpisodeRenderer:
    def __init__(
        self, model: mujoco.MjModel, width: int = 480, height: int = 360, camera: str = "front"
    ) -> None:
        self.model, self.camera = model, camera
        self.renderer = mujoco.Renderer(model, height, width)
        self.tint = JointTint(model)

    def render(
        self,
        data: mujoco.MjData,
        scores: Sequence[float] | None = None,
        overlay: Sequence[tuple[str, tuple[int, int, int]]] = (),
    ) -> np.ndarray:
        self.tint.apply(scores)
        self.renderer.update_scene(data, camera=self.camera)
        image = self.renderer.render()
        return draw_overlay(image, overlay) if overlay else image

    def close(self) -> None:
        self.renderer.close()


def write_video(frames: Iterator[np.ndarray] | list[np.ndarray], path: str, fps: float) -> None:
    """GIF or MP4 by extension (MP4 needs imageio-ffmpeg)."""
    import imageio.v2 as imageio

    if path.lower().endswith(".gif"):
        imageio.mimsave(path, list(frames), duration=1.0 / fps, loop=0)
    else:
        with imageio.get_writer(
            path, fps=fps, codec="libx264", quality=7, macro_block_size=1
        ) as writer:
            for frame in frames:
                writer.append_data(frame)
