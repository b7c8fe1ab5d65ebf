"""One model across arms: channels relative to each joint's ratings, a model trained for transfer
reads an arm it never saw, one that was not refuses it, and the exported model reads the raw
readings of the arm it was exported for."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnxruntime as ort
import pytest

from robohealth_mj import schema
from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.config import compose_config
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.relative import channel_scale, to_raw, to_relative
from robohealth_mj.deploy.commission import commission
from robohealth_mj.deploy.export import export_checkpoint
from robohealth_mj.learn.checkpoint import checkpoint_arm, load_checkpoint
from robohealth_mj.learn.evaluation import evaluate_checkpoint
from robohealth_mj.learn.run import train_and_evaluate
from robohealth_mj.recording.recorder import record_session

# a booster of a few small trees: these tests check which arms a model reads, not how well
SMALL_BOOSTER = ["model.rounds=20", "model.num_leaves=7"]
VEL, EFFORT, RESIDUAL, POS = (schema.feature_index(n)
                              for n in ("vel", "effort", "effort_residual", "pos"))  # fmt: skip


def _record(root: Path, arm: str, seed: int, overrides: list[str]) -> Path:
    out = root / f"{arm}_seed{seed}"
    cfg = compose_config("record", [*overrides, f"arm={arm}", f"seed={seed}"])
    record_session(cfg, out)
    return out / "graphs.jsonl"


def test_the_ur5e_reads_as_recorded_and_other_arms_relative_to_their_ratings():
    assert np.all(channel_scale("ur5e") == 1.0)  # every earlier figure stands
    ur16e, ur5e = load_arm("ur16e"), load_arm("ur5e")
    scale = channel_scale("ur16e")
    for node in (2, 2 + schema.N_JOINTS):  # the elbow and the copy on its sensor node
        assert scale[node, EFFORT] == pytest.approx(150.0 / 150.0)  # both elbows: 150 N m
        assert scale[node, VEL] == pytest.approx(ur5e.speed_limit[2] / ur16e.speed_limit[2])
    assert scale[0, EFFORT] == pytest.approx(150.0 / 330.0)  # the UR16e's base: 330 N m
    assert scale[0, RESIDUAL] == scale[0, EFFORT]
    assert scale[0, VEL] == pytest.approx(180.0 / 120.0)
    assert np.all(scale[:, POS] == 1.0)  # angles mean the same on every arm


def test_two_arms_at_the_same_relative_load_and_speed_read_alike():
    """The same share of each joint's rated torque and speed limit on a UR3e and a UR16e gives
    the same relative channels, though the raw ones differ by up to 12x."""
    rng = np.random.default_rng(0)
    share = rng.uniform(-1, 1, size=(50, schema.N_JOINTS, 3))
    raw = {}
    for arm in ("ur3e", "ur16e"):
        a = load_arm(arm)
        x = rng.normal(size=(50, schema.N_NODES, schema.N_FEATURES)).astype(np.float32)
        for nodes in (slice(0, 6), slice(6, 12)):
            x[:, nodes, EFFORT] = share[..., 0] * a.rated_torque
            x[:, nodes, RESIDUAL] = share[..., 1] * a.rated_torque
            x[:, nodes, VEL] = share[..., 2] * a.speed_limit
        raw[arm] = x
    cols = [EFFORT, RESIDUAL, VEL]
    assert not np.allclose(raw["ur3e"][..., cols], raw["ur16e"][..., cols], rtol=0.05)
    rel = {arm: to_relative(x, arm) for arm, x in raw.items()}
    np.testing.assert_allclose(rel["ur3e"][..., cols], rel["ur16e"][..., cols], rtol=1e-5)
    np.testing.assert_allclose(to_raw(rel["ur3e"], "ur3e"), raw["ur3e"], rtol=1e-6)


def test_the_curriculum_moves_every_arm_alike_in_relative_speed(tmp_path):
    """The same seed on a UR3e (wrists 360 deg/s) and a UR16e (shoulders 120 deg/s): the joint
    speeds a recording holds, read relative to the limits, agree to a few per cent (the arms
    track their common relative reference differently); raw, they differ by most of their
    size."""
    healthy = ["faults=none", "session.duration_s=4", "session.progress=false"]
    files = {arm: _record(tmp_path, arm, 7, healthy) for arm in ("ur3e", "ur16e")}
    x = {arm: load_recordings([f]).x for arm, f in files.items()}
    rel = {arm: v[:, :6, VEL] for arm, v in x.items()}
    raw = {arm: to_raw(v, arm)[:, :6, VEL] for arm, v in x.items()}

    def rms(v: np.ndarray) -> float:
        return float(np.sqrt(np.mean(v**2)))

    rel_gap, raw_gap = rms(rel["ur3e"] - rel["ur16e"]), rms(raw["ur3e"] - raw["ur16e"])
    assert rel_gap < 0.1 * rms(rel["ur3e"])  # measured: 5 % (the heavier arm lags more)
    assert raw_gap > 10 * rel_gap  # measured: 13x


@pytest.mark.slow  # trains three models
def test_a_model_reads_an_unseen_arm_only_when_trained_for_transfer(tmp_path, fast_session):
    train = [_record(tmp_path / "train", arm, seed, fast_session)
             for arm, seed in (("ur5e", 1), ("ur5e", 2), ("ur10e", 3), ("ur10e", 4))]  # fmt: skip
    unseen = _record(tmp_path, "ur3e", 5, fast_session)

    def trained(name: str, *overrides: str) -> Path:
        cfg = compose_config("train", [
            f"data.train=[{tmp_path}/train/*]", "data.evaluate.heldout=null",
            "data.evaluate.probe=null", "trainer.progress=false", "window=8", *overrides,
        ])  # fmt: skip
        train_and_evaluate(cfg, tmp_path / name)
        return tmp_path / name / "best.ckpt"

    plain = trained("plain", "variant=gbdt", *SMALL_BOOSTER)
    with pytest.raises(InputError, match=r"a recording of a ur3e; the model was trained on "
                                         r"ur10e, ur5e .*transfer=true"):  # fmt: skip
        evaluate_checkpoint(plain, str(unseen))
    evaluate_checkpoint(plain, str(train[2]))  # its own arms read

    transfer = trained("transfer", "variant=gbdt", "transfer=true", *SMALL_BOOSTER)
    metrics = evaluate_checkpoint(transfer, str(unseen))["metrics"]
    assert 0.0 <= metrics["accuracy"] <= 1.0

    with pytest.raises(InputError, match=r"transfer=true needs training recordings of two arms"):
        cfg = compose_config("train", [f"data.train=[{train[0]}]", "transfer=true"])
        train_and_evaluate(cfg, tmp_path / "one_arm")

    # a network exported for the UR3e takes its raw readings; the same model exported for the
    # UR5e reads them on the wrong scale
    net = trained("net", "variant=stgnn_fixed", "model.hidden=8", "trainer.epochs=1",
                  "transfer=true")  # fmt: skip
    for_ur3e = export_checkpoint(net, tmp_path / "ur3e.onnx", data=str(unseen))
    assert for_ur3e["metadata"]["arm"] == "ur3e" and for_ur3e["parity_error"] <= 1e-4
    for_ur5e = export_checkpoint(net, tmp_path / "ur5e.onnx", data=str(train[0]))
    assert for_ur5e["metadata"]["arm"] == "ur5e"
    raw = to_raw(load_recordings([unseen]).x[:8], "ur3e")[None]  # one window, W = 8

    def logits(path: str) -> np.ndarray:
        session = ort.InferenceSession(path, providers=["CPUExecutionProvider"])
        return session.run(None, {"x": raw})[0]

    assert not np.allclose(logits(for_ur3e["path"]), logits(for_ur5e["path"]), atol=1e-3)


@pytest.mark.slow  # records six sessions, fits one booster
def test_arms_of_two_joint_counts_train_one_model_that_reads_a_third(tmp_path, fast_session):
    """A Franka's, a KUKA's and a UR5e's recordings train one model on the seven-joint positional
    graph (the UR's joints placed on it); it scores a Kinova it never saw, and commissioned on
    the Kinova's healthy running (its reference the three arms' data, placed again) it is the
    Kinova's model: its checkpoint names the Kinova's joints and refuses the Franka's."""
    session = [o for o in fast_session if not o.startswith("faults.schedule.joints")]
    for arm, seed in (("fr3", 1), ("fr3", 2), ("iiwa14", 3), ("ur5e", 6)):
        _record(tmp_path / "train", arm, seed, session)
    unseen = _record(tmp_path, "gen3", 4, session)
    healthy = _record(tmp_path, "gen3", 5, ["faults=none", "session.duration_s=30",
                                            "session.progress=false"])  # fmt: skip
    cfg = compose_config("train", [
        f"data.train=[{tmp_path}/train/*]", "data.evaluate.heldout=null", "variant=gbdt",
        "data.evaluate.probe=null", "trainer.progress=false", "window=8", "transfer=true",
        *SMALL_BOOSTER,
    ])  # fmt: skip
    train_and_evaluate(cfg, tmp_path / "model")
    model = tmp_path / "model" / "best.ckpt"
    assert checkpoint_arm(load_checkpoint(model)) == schema.ArmGraph.by_position(7)
    metrics = evaluate_checkpoint(model, str(unseen))["metrics"]
    assert 0.0 <= metrics["localisation_accuracy"] <= 1.0

    commission(model, str(healthy), tmp_path / "gen3", export=False)
    kinova = load_recordings([unseen]).graph
    assert kinova.joints[0] == "joint_1" and not kinova.positional
    commissioned = tmp_path / "gen3" / "best.ckpt"
    assert checkpoint_arm(load_checkpoint(commissioned)) == kinova
    again = evaluate_checkpoint(commissioned, str(unseen))["metrics"]
    assert 0.0 <= again["accuracy"] <= 1.0
    with pytest.raises(InputError, match=r"an arm of joints .*fr3_joint1.*trained on .*joint_1"):
        evaluate_checkpoint(commissioned, str(next((tmp_path / "train").glob("fr3*"))))
