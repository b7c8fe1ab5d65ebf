"""One fault episode simulated, diagnosed as it runs and rendered offscreen: the true fault and
the diagnosis as an overlay, each joint housing tinted by its localisation score
(``python -m robohealth_mj.render``; the drawing itself is :mod:`robohealth_mj.deploy.render`)."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # before anything imports mujoco

from pathlib import Path

import numpy as np
from omegaconf import DictConfig

from robohealth_mj.common.config import arm_choice, arm_override, compose_config


def localisation_tint(joint_scores: dict[str, float]) -> np.ndarray:
    """Per-joint tint in [0, 1]: how far the joint's share of the localisation evidence
    (a softmax over the joint logits) rises above uniform. Flat evidence tints nothing."""
    s = np.clip(np.array(list(joint_scores.values())), 1e-6, 1 - 1e-6)
    logits = np.log(s / (1 - s))
    p = np.exp(logits - logits.max())
    p /= p.sum()
    uniform = 1.0 / len(p)
    return np.clip((p - uniform) / (1.0 - uniform), 0.0, 1.0)


def render_episode(cfg: DictConfig) -> list:
    from PIL import Image

    from robohealth_mj.data.jsonl import format_line
    from robohealth_mj.deploy.render import EpisodeRenderer, write_video
    from robohealth_mj.recording.recorder import build_simulator, chunk_features
    from robohealth_mj.runtime.runtime import ModelRuntime

    runtime = ModelRuntime(cfg.model)
    arm = arm_choice(cfg) or (runtime.fleet.arm if runtime.fleet.engine is not None else "ur5e")
    record = compose_config(
        "record",
        [
            *arm_override(f"arm={arm}"),
            "session.progress=false",
            f"seed={cfg.seed}",
            "session.chunk_s=0.05",
            "faults=fixed",
            f"faults.fault_model={cfg.fault_model}",
            f"faults.schedule.fault_class={cfg.fault}",
            f"faults.schedule.joint={cfg.joint}",
            f"faults.schedule.severity={cfg.severity}",
            f"faults.schedule.onset_s={cfg.onset_s}",
        ],
    )
    sim = build_simulator(record)
    view = EpisodeRenderer(sim.model, cfg.width, cfg.height, cfg.camera)
    every = max(1, round(1.0 / (cfg.fps * sim.tick_s)))
    frames, png_dir = [], Path(cfg.png_dir) if cfg.png_dir else None
    if png_dir:
        png_dir.mkdir(parents=True, exist_ok=True)
    segment = {"index": 0, "family": "render", "speed_scale": 1.0, "payload_scale": 1.0}
    for k, chunk in enumerate(sim.run(round(cfg.duration_s / sim.tick_s))):
        x = chunk_features(chunk)[0]
        d = runtime.process(
            "render",
            format_line("render", k, float(chunk.t[0]), x, chunk.fault, segment, sim.graph),
        )
        if k % every:
            continue
        truth = chunk.fault
        true_text = (
            f"TRUE  {truth.fault_class} @ {truth.joint}  severity {truth.severity:g}"
            if truth.active
            else "TRUE  healthy"
        )
        if d.fault_class is None:
            diag_text, scores = f"MODEL {d.reason}", None
        else:
            where = f" @ {d.localised_joint}" if d.fault_present else ""
            diag_text = f"MODEL {d.fault_class}{where}  p={d.confidence:.2f}"
            scores = localisation_tint(d.joint_scores) if d.fault_present else None
        image = view.render(
            sim.data,
            scores,
            [
                (f"t = {chunk.t[0]:6.2f} s   {d.model_id}", (200, 200, 200)),
                (true_text, (255, 210, 80)),
                (diag_text, (120, 220, 255)),
            ],
        )
        frames.append(image)
        if png_dir:
            Image.fromarray(image).save(png_dir / f"frame_{len(frames):04d}.png")
    view.close()
    if cfg.out:
        Path(cfg.out).parent.mkdir(parents=True, exist_ok=True)
        write_video(frames, str(cfg.out), cfg.fps)
    return frames
