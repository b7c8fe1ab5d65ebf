"""Commissioning a model on a new arm from its healthy running: the residual baseline moves by
what the arm adds, a nominal arm's model stays as it was, and the commissioned ONNX carries it."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import numpy as np
import onnxruntime as ort
import pytest

from robohealth_mj import schema
from robohealth_mj.commission import main as commission_main
from robohealth_mj.common.config import compose_config
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.baseline import RESIDUALS, basis
from robohealth_mj.data.windows import make_windows
from robohealth_mj.deploy.commission import commission
from robohealth_mj.deploy.operating_point import check_recipe, per_class_offset
from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checkpoint
from robohealth_mj.recording.recorder import record_session
from robohealth_mj.runtime.contact import ContactPolicy
from robohealth_mj.runtime.metadata import read_metadata
from robohealth_mj.runtime.runtime import ModelRuntime
from robohealth_mj.runtime.sources import replay_stream

J = schema.N_JOINTS
ELBOW, RESIDUAL = 2, schema.feature_index("effort_residual")
OFFSET = 0.8  # N*m: what this arm's elbow adds to the controller's torque residual


@pytest.fixture(scope="module")
def healthy(tmp_path_factory) -> dict[str, Path]:
    """40 s of healthy running of the nominal arm, the same with the elbow's torque residual
    offset (an arm whose controller model is off by a constant there), and 40 s of a
    pick-and-place program (motion unlike the training sweeps)."""
    root = tmp_path_factory.mktemp("healthy")
    cfg = compose_config("record", ["session.progress=false", "faults=none", "seed=5",
                                    "session.duration_s=40"])  # fmt: skip
    record_session(cfg, root / "nominal")
    program = ["session.progress=false", "faults=none", "seed=8", "session.duration_s=40",
               "curriculum.families=[pick_place]"]  # fmt: skip
    record_session(compose_config("record", program), root / "program")
    lines = (root / "nominal" / "graphs.jsonl").read_text().splitlines()
    shifted = []
    for line in lines:
        obj = json.loads(line)
        for node in (ELBOW, J + ELBOW):  # the joint and the copy on its sensor node
            obj["x"][node][RESIDUAL] += OFFSET
        shifted.append(json.dumps(obj))
    (root / "offset").mkdir()
    (root / "offset" / "graphs.jsonl").write_text("\n".join(shifted) + "\n")
    return {"nominal": root / "nominal", "offset": root / "offset", "program": root / "program"}


def _windows(path: Path, window: int) -> np.ndarray:
    x = load_recordings([path / "graphs.jsonl"]).x
    return np.ascontiguousarray(np.stack([x[k : k + window] for k in range(0, 600, 25)]))


def test_an_offset_moves_the_baseline_by_it_and_the_onnx_undoes_it(
    stock_deployed, healthy, tmp_path
):
    ckpt = stock_deployed["ckpt"]
    reference = str(Path(stock_deployed["heldout"]).parents[1] / "train_*")
    plain = commission(ckpt, str(healthy["nominal"]), tmp_path / "a", reference)
    offset = commission(ckpt, str(healthy["offset"]), tmp_path / "b", reference)
    shift_a = graph_from_checkpoint(load_checkpoint(plain["checkpoint"])).baseline_shift
    shift_b = graph_from_checkpoint(load_checkpoint(offset["checkpoint"])).baseline_shift
    x = load_recordings([healthy["offset"] / "graphs.jsonl"]).x
    moved = np.einsum("tjb,jcb->tjc", basis(x), shift_b - shift_a)  # [T, 6, 2] per tick
    expected = np.zeros_like(moved)
    expected[:, ELBOW, RESIDUALS.index("effort_residual")] = OFFSET
    np.testing.assert_allclose(moved, expected, atol=2e-3)  # the elbow residual's offset, only

    meta = read_metadata(offset["onnx"])
    assert meta["commissioning_data_fingerprint"] == offset["healthy_fingerprint"]
    assert float(meta["commissioning_healthy_minutes"]) == pytest.approx(40 / 60, abs=0.01)
    window = int(load_checkpoint(ckpt)["window"])
    runs = {}
    for name, onnx in (("a", plain["onnx"]), ("b", offset["onnx"])):
        session = ort.InferenceSession(onnx, providers=["CPUExecutionProvider"])
        data = healthy["nominal" if name == "a" else "offset"]
        runs[name] = session.run(None, {"x": _windows(data, window)})[0]
    np.testing.assert_allclose(runs["a"], runs["b"], atol=1e-3)  # the offset arm reads as nominal


def test_commissioning_a_nominal_arm_leaves_its_model_as_it_was(stock_deployed, healthy, tmp_path):
    """Commissioned on the model's own kind of arm, the baseline barely moves and the exported
    model decides as the uncommissioned one."""
    ckpt = stock_deployed["ckpt"]
    reference = str(Path(stock_deployed["heldout"]).parents[1] / "train_*")
    record = commission(ckpt, str(healthy["nominal"]), tmp_path / "c", reference)
    window = int(load_checkpoint(ckpt)["window"])
    x = _windows(healthy["nominal"], window)
    before, after = (
        ort.InferenceSession(str(p), providers=["CPUExecutionProvider"]).run(None, {"x": x})[0]
        for p in (stock_deployed["onnx"], record["onnx"])
    )
    assert np.array_equal(before.argmax(1), after.argmax(1))
    assert np.abs(before - after).max() < 0.5  # logits; the same decisions
    assert record["settling"][0]["minutes"] == 0.5 and record["healthy_minutes"] < 1


def test_commission_refuses_faulted_data_in_one_line(stock_deployed, capsys):
    with pytest.raises(SystemExit) as done:
        commission_main([f"model={stock_deployed['ckpt']}", f"healthy={stock_deployed['heldout']}"])
    err = capsys.readouterr().err.strip()
    assert done.value.code == 2 and "\n" not in err
    assert "carry an active fault; commission on healthy running only" in err


def _onnx_healthy_rate(onnx: str, data: Path, ckpt: str) -> float:
    """How often the exported model calls the windows of ``data`` healthy."""
    rec = load_recordings([data / "graphs.jsonl"])
    windows = make_windows(rec, int(load_checkpoint(ckpt)["window"]))
    x = np.stack([rec.x[s : s + windows.window] for s in windows.start])
    session = ort.InferenceSession(onnx, providers=["CPUExecutionProvider"])
    return float((session.run(None, {"x": x})[0].argmax(1) == 0).mean())


def test_commissioning_matches_the_healthy_operating_point(deployed, healthy, tmp_path):
    """The ``healthy`` recipe: on a program unlike its training sweeps, the arm's healthy
    windows are called healthy at the rate the model calls its validation session's, and the
    exported model decides with the raised healthy logit."""
    ckpt = deployed["structural_ckpt"]
    reference = str(Path(deployed["root"]) / "train_*")
    record = commission(ckpt, str(healthy["program"]), tmp_path, reference,
                        operating_point="healthy")  # fmt: skip
    point = record["operating_point"]
    assert point["validation_windows"] > 0 and point["arm_windows"] > 0
    tolerance = 1.0 / point["arm_windows"]
    # the program's healthy running looks less healthy than the validation session's ...
    assert point["arm_healthy_rate_before"] < point["validation_healthy_rate"] - 5 * tolerance
    assert point["healthy_offset"] > 0.0  # ... so the healthy logit is raised
    assert point["arm_healthy_rate_after"] == pytest.approx(
        point["validation_healthy_rate"], abs=tolerance
    )
    called_healthy = _onnx_healthy_rate(record["onnx"], healthy["program"], ckpt)
    assert called_healthy == pytest.approx(point["arm_healthy_rate_after"], abs=tolerance)


def test_per_class_matching_lowers_only_what_healthy_running_is_mistaken_for():
    """Healthy running called jam far more often than in validation: jam's logit is lowered
    just enough to bring that rate back, the windows it hands to friction lower friction in
    turn, and a class healthy running is not mistaken for keeps its logit, so a clear
    backlash window is still called backlash."""
    rng = np.random.default_rng(0)
    validation = np.zeros((200, 5), np.float32)
    validation[:, 0] = 1.0
    validation[:4, 3] = 2.0  # 2 % of validation's healthy windows called jam
    arm = np.zeros((200, 5), np.float32)
    arm[:, 0] = 1.0
    arm[:60, 3] = 1.5 + rng.uniform(0.0, 1.0, 60)  # 30 % called jam ...
    arm[:20, 2] = 1.4  # ... a third of them with friction next
    offset = per_class_offset(validation, arm)
    assert offset[0] == 0.0 and offset[1] == 0.0 and offset[4] == 0.0
    assert offset[3] < 0.0 and offset[2] < 0.0
    called = (arm + offset).argmax(1)
    assert (called == 3).mean() == pytest.approx(0.02, abs=1 / 200)  # no lower than needed
    assert (called == 2).mean() <= 1 / 200  # validation never calls friction: one window
    backlash = np.array([[1.0, 1.2, 0.0, 0.0, 0.0]], np.float32)
    assert (backlash + offset).argmax(1)[0] == 1


def test_a_healthy_rate_asked_for_is_stricter_than_validations():
    """healthy_rate=0.99: each of the four fault classes may take a quarter of the 1 % left
    (validation's 2 % of jam is no longer enough), and a clear fault is still called; a rate
    outside (0, 1), or with the healthy recipe, is one line."""
    rng = np.random.default_rng(1)
    validation = np.zeros((400, 5), np.float32)
    validation[:, 0] = 1.0
    validation[:8, 3] = 2.0  # 2 % called jam
    arm = np.zeros((400, 5), np.float32)
    arm[:, 0] = 1.0
    arm[:, 1:] = rng.uniform(0.0, 1.4, (400, 4))  # every class a little, some above healthy
    offset = per_class_offset(validation, arm, healthy_rate=0.99)
    called = (arm + offset).argmax(1)
    assert (called == 0).mean() >= 0.99 - 1 / 400
    assert max((called == k).mean() for k in range(1, 5)) <= 0.0025 + 1 / 400
    assert (np.array([[1.0, 0.0, 0.0, 3.5, 0.0]], np.float32) + offset).argmax(1)[0] == 3
    assert ((arm + per_class_offset(validation, arm)).argmax(1) == 0).mean() < 0.98
    for recipe, rate in (("per_class", 1.5), ("healthy", 0.99)):
        with pytest.raises(InputError, match=r"healthy_rate: a number in \(0, 1\)"):
            check_recipe(recipe, rate)


def test_commissioning_matches_each_fault_class_by_default(deployed, healthy, tmp_path):
    """The default ``per_class`` recipe: the program's healthy windows are called each fault
    class no more often than the validation session's are, only fault logits move (down),
    and the exported model decides with them."""
    ckpt = deployed["structural_ckpt"]
    reference = str(Path(deployed["root"]) / "train_*")
    record = commission(ckpt, str(healthy["program"]), tmp_path, reference)
    point = record["operating_point"]
    assert point["recipe"] == "per_class"
    offset = np.asarray(point["class_offset"])
    assert offset[0] == 0.0 and (offset <= 0.0).all() and (offset < 0.0).any()
    tolerance = 1.0 / point["arm_windows"]
    assert point["arm_healthy_rate_after"] > point["arm_healthy_rate_before"] + 5 * tolerance
    called_healthy = _onnx_healthy_rate(record["onnx"], healthy["program"], ckpt)
    assert called_healthy == pytest.approx(point["arm_healthy_rate_after"], abs=tolerance)


def test_an_unknown_operating_point_recipe_is_one_line(stock_deployed, healthy, capsys):
    with pytest.raises(SystemExit) as done:
        commission_main([f"model={stock_deployed['ckpt']}", f"healthy={healthy['nominal']}",
                         "operating_point=median", "export=false",
                         f"out={healthy['nominal'].parent / 'unknown_recipe'}"])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert done.value.code == 2 and "\n" not in err
    assert "operating_point must be one of ('per_class', 'healthy'), got 'median'" in err
    with pytest.raises(SystemExit) as done:
        commission_main([f"model={stock_deployed['ckpt']}", f"healthy={healthy['nominal']}",
                         "contact_margin=0", "export=false"])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert done.value.code == 2 and "\n" not in err
    assert "contact_margin: must be positive (or null), got 0" in err


@pytest.mark.slow
def test_a_model_that_reads_no_residual_gets_no_settling_table(tiny_corpus, healthy, tmp_path):
    """A retrofit model reads no tracking error or torque residual on its joints, so how long
    their baseline took to settle says nothing about it: commissioning says so instead of
    printing a table (the stock model above, which reads them, gets the table)."""
    from robohealth_mj.learn.run import train_and_evaluate as run

    cfg = compose_config("train", [
        f"data.train=[{tiny_corpus}/train_*]", "data.evaluate=null", "trainer.progress=false",
        "window=8", "sensing=retrofit", "variant=mlp", "model.hidden=8", "trainer.epochs=1",
    ])  # fmt: skip
    run(cfg, tmp_path / "run")
    record = commission(tmp_path / "run" / "best.ckpt", str(healthy["nominal"]), tmp_path / "c",
                        export=False)  # fmt: skip
    assert record["settling"] == [] and record["settled_minutes"] is None
    assert "'retrofit' reads no residual channel" in record["settling_skipped"]


HOLD = ["session.progress=false", "faults=none", "curriculum.families=[hold]"]
PUSH = "{at_s: 8, for_s: 1, link: forearm_link, force_n: [0, 40, 0], point_m: [-0.2, 0, 0.05]}"


def test_commissioning_fits_the_contact_watch_and_the_monitor_calls_a_push_with_it(
    stock_deployed, healthy, tmp_path
):
    """Healthy running that holds a pose gives the contact watch its thresholds, which ride in
    the exported model; the monitor then calls a simulated push on the forearm at the elbow,
    while it lasts, and nothing on healthy running. Running that never rests gives none."""
    ckpt = stock_deployed["ckpt"]
    reference = str(Path(stock_deployed["heldout"]).parents[1] / "train_*")
    for name, extra in (("hold", []), ("pushed", [f"session.pushes=[{PUSH}]"])):
        cfg = compose_config("record", [*HOLD, "seed=3", "session.duration_s=12", *extra])
        record_session(cfg, tmp_path / name)
    record = commission(ckpt, str(tmp_path / "hold"), tmp_path / "c", reference)
    thresholds = record["contact"]["threshold_nm"]
    assert len(thresholds) == J and min(thresholds) > 0
    meta = read_metadata(record["onnx"])
    assert json.loads(meta["contact_threshold_nm"]) == thresholds
    placing = json.loads(meta["contact_placing"])  # the arm's surface and the fit's noise
    assert np.allclose(np.array(placing["noise_nm"]) * 2.0, thresholds, rtol=1e-3)
    assert len(placing["surface"]["link"]) == len(placing["surface"]["point"]) > 1000
    assert len(json.dumps(record["contact"])) < 500  # the record stays readable: no surface

    def contacts(data: Path, **kwargs) -> list:
        runtime = ModelRuntime(record["onnx"], **kwargs)
        said = [runtime.process("arm", s) for _, s, _ in replay_stream(str(data / "graphs.jsonl"))]
        return [d.contact_joint for d in said]

    assert not any(contacts(tmp_path / "hold"))
    called = contacts(tmp_path / "pushed", contact=ContactPolicy())
    during = [j for j in called[160:181] if j]  # the push: ticks 160-180 (8 s for 1 s)
    assert len(during) >= 15 and Counter(during).most_common(1)[0][0] == "elbow"
    assert not any(called[:160]) and not any(called[183:])
    off = contacts(tmp_path / "pushed", contact=ContactPolicy(enabled=False))
    assert not any(off)
    sweeps = commission(ckpt, str(healthy["nominal"]), tmp_path / "s", reference, export=False)
    assert "no quiet of 25 ticks" in sweeps["contact"]["skipped"]


def test_a_refitted_normalisation_reads_the_arms_healthy_running_as_the_training_arms(
    stock_deployed, healthy, tmp_path
):
    """``normalisation=moments``: the commissioned checkpoint z-scores this arm's healthy running
    (a program unlike the training sweeps) to the mean and spread the training normalisation gave
    the training arms' healthy running, node by node; without it, it does not."""
    ckpt = stock_deployed["ckpt"]
    reference = str(Path(stock_deployed["heldout"]).parents[1] / "train_*")
    trained = load_checkpoint(ckpt)
    ref = load_recordings(sorted(Path(reference).parent.glob("train_*/graphs.jsonl")))
    ref_nodes = graph_from_checkpoint(trained).transform(ref.x[~ref.active])
    z_ref = (ref_nodes - trained["norm_mean"].numpy()) / trained["norm_std"].numpy()
    live = ref_nodes.std(0) > 1e-3
    program = load_recordings([healthy["program"] / "graphs.jsonl"]).x

    def z_program(out: str, normalisation: str) -> np.ndarray:
        record = commission(ckpt, str(healthy["program"]), tmp_path / out, reference,
                            export=False, normalisation=normalisation)  # fmt: skip
        done = load_checkpoint(record["checkpoint"])
        nodes = graph_from_checkpoint(done).transform(program)
        return (nodes - done["norm_mean"].numpy()) / done["norm_std"].numpy()

    matched, kept = z_program("moments", "moments"), z_program("kept", "none")
    live &= program.std(0)[: live.shape[0]] > 1e-3
    np.testing.assert_allclose(matched.mean(0)[live], z_ref.mean(0)[live], atol=1e-3)
    np.testing.assert_allclose(matched.std(0)[live], z_ref.std(0)[live], rtol=1e-3)
    assert np.abs(kept.std(0)[live] - z_ref.std(0)[live]).max() > 0.1


def test_an_unknown_normalisation_is_one_line(stock_deployed, healthy, capsys):
    with pytest.raises(SystemExit) as done:
        commission_main([f"model={stock_deployed['ckpt']}", f"healthy={healthy['nominal']}",
                         "normalisation=moment"])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert done.value.code == 2 and "\n" not in err
    assert "normalisation: one of none, sensors, shift, moments, got 'moment'" in err
