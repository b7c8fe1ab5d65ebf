"""Headless rendering: non-blank frames, and the joint tint really changes the picture."""

from __future__ import annotations

import mujoco
import numpy as np

from robohealth_mj.common.config import compose_config
from robohealth_mj.deploy.episode import render_episode
from robohealth_mj.deploy.render import EpisodeRenderer
from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.model import HOME_POSE, ArmIndex, build_model


def test_a_tinted_joint_changes_its_pixels():
    model = build_model()
    data = mujoco.MjData(model)
    ArmIndex.of(model).set_link_pose(data, HOME_POSE)
    mujoco.mj_forward(model, data)
    view = EpisodeRenderer(model, width=160, height=120, camera="front")
    view.render(data, None)  # the first frame after creating a context can differ
    plain = view.render(data, None).astype(int)
    scores = np.zeros(6)
    scores[JOINT_NAMES.index("elbow")] = 1.0
    tinted = view.render(data, scores).astype(int)
    again = view.render(data, None).astype(int)
    view.close()
    assert plain.std() > 10  # not blank
    changed = np.abs(tinted - plain).sum(axis=-1) > 30
    assert changed.sum() > 20  # the elbow housing turned red
    shift = (tinted - plain)[changed].mean(axis=0)  # the housing and its floor reflection
    assert shift[0] > 20 and shift[2] < -20  # towards red, away from UR blue
    np.testing.assert_array_equal(again, plain)  # and back


def test_render_cli_writes_frames_gif_and_pngs(tmp_path):
    cfg = compose_config(
        "render",
        [
            f"out={tmp_path / 'ep.gif'}",
            f"png_dir={tmp_path / 'png'}",
            "duration_s=1.0",
            "onset_s=0.5",
            "fps=5",
            "width=160",
            "height=120",
        ],
    )
    frames = render_episode(cfg)
    assert len(frames) == 5
    assert all(f.shape == (120, 160, 3) and f.std() > 10 for f in frames)
    assert (tmp_path / "ep.gif").read_bytes()[:6] == b"GIF89a"
    assert len(list((tmp_path / "png").glob("frame_*.png"))) == 5
    # the overlay band at the top is drawn (dark, with text pixels)
    assert frames[0][:20].mean() < frames[0][40:].mean()


def test_a_seven_joint_arm_renders_with_its_own_joints_tinted(tmp_path):
    """``render arm=fr3``: the FR3 simulated, its fault named by its joint; its seven housings
    are the ones a diagnosis tints."""
    from robohealth_mj.deploy.render import JointTint
    from robohealth_mj.sim.model import build_model

    tint = JointTint(build_model("fr3"))
    assert len(set(tint.geoms)) == 7
    tint.apply([0.0] * 6 + [1.0])  # the tool joint red, the others as they were
    assert tint.model.geom_rgba[tint.geoms[-1]][0] > 0.9 > tint.model.geom_rgba[tint.geoms[0]][0]
    cfg = compose_config(
        "render",
        ["arm=fr3", "joint=fr3_joint4", "duration_s=0.5", "onset_s=0.2", "fps=4", "width=96",
         "height=72", "out=null"],
    )  # fmt: skip
    frames = render_episode(cfg)
    assert len(frames) == 2 and all(f.std() > 10 for f in frames)
