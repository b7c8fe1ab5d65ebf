"""Placement self-calibration: training under drawn placements (each window mixed by a placement
the model is given), and commissioning that refits a harness model's coupling C alone on an
arm's healthy running."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import torch
from torch import nn

from robohealth_mj import schema
from robohealth_mj.commission import main as commission_main
from robohealth_mj.common.config import compose_config
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.graphs import DEFAULT_C0, coupling_correlation, harness_graph, load_coupling
from robohealth_mj.deploy.commission import commission
from robohealth_mj.deploy.recouple import reconstruction_estimate
from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checkpoint
from robohealth_mj.learn.checkpoint import model_from_checkpoint as build
from robohealth_mj.learn.motion_placement import motion_estimate, sparse_mixture
from robohealth_mj.learn.placements import (
    PlacementPool,
    healthy_sensor_statistics,
    mixed_statistics,
)
from robohealth_mj.learn.run import train_and_evaluate as run
from robohealth_mj.models.heads import AnomalyResidualHead
from robohealth_mj.recording.recorder import record_session
from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime

pytestmark = pytest.mark.slow  # every test here trains a model

J, S = schema.N_JOINTS, schema.SENSOR_CHANNELS
OPTIONS = ("coupled_edges", "anomaly_joint_scores", "placement_embedding")
POS, VEL = schema.feature_index("pos"), schema.feature_index("vel")


def _snapshots(n: int = 400, seed: int = 0) -> np.ndarray:
    """Schema snapshots ``[n, 12, F]`` whose six sensor packages differ in scale and share a
    common component (so the mixed variances depend on the packages' covariance)."""
    rng = np.random.default_rng(seed)
    x = np.zeros((n, schema.N_NODES, schema.N_FEATURES), np.float32)
    common = rng.normal(size=(n, 1, 1))
    x[:, J:, S] = rng.normal(size=(n, J, 8)) * np.arange(1, J + 1)[None, :, None] + common + 3
    x[:, :J, 0], x[:, J:, 1] = 1.0, 1.0
    return x


def test_mixed_statistics_are_those_of_the_mixed_sensors():
    x = _snapshots()
    c = harness_graph(coupling_seed=3).coupling
    pkg = x[:, J:, S].astype(np.float64)
    centred = pkg - pkg.mean(0)
    cov = np.einsum("tjc,tkc->cjk", centred, centred) / (len(x) - 1)
    mu, sd = mixed_statistics(c, pkg.mean(0), cov)
    mixed = harness_graph(coupling=c).transform(x)[:, J:, S]
    np.testing.assert_allclose(mu, mixed.mean(0), rtol=1e-4)
    np.testing.assert_allclose(sd, mixed.std(0, ddof=1), rtol=1e-3)


def test_each_window_is_mixed_by_the_placement_it_is_given():
    x = _snapshots()
    graph = harness_graph()
    pool = PlacementPool(graph, x, np.ones(len(x), bool), 5, torch.device("cpu"))
    assert len({tuple(c.ravel().tolist()) for c in pool.couplings}) == 5
    snapshots = torch.arange(64).reshape(8, 8)  # eight windows of eight snapshots
    base = torch.from_numpy(graph.transform(x))[snapshots]
    mixed, couplings = pool.mix(base, snapshots, torch.Generator().manual_seed(1))
    for b in range(8):
        c = couplings[b].numpy()
        k = int(((pool.couplings - couplings[b]).abs().amax(dim=(1, 2)) == 0).nonzero()[0])
        want = harness_graph(coupling=c).transform(x[snapshots[b].numpy()])[:, J:, S]
        mu, sd = pool.statistics(c)
        np.testing.assert_allclose(pool.mean[k].numpy(), mu)
        np.testing.assert_allclose(mixed[b, :, J:, S].numpy(), (want - mu) / sd, atol=1e-4)
    torch.testing.assert_close(mixed[:, :, :J], base[:, :, :J])  # joints untouched
    again, same = pool.mix(base, snapshots, torch.Generator().manual_seed(1))
    torch.testing.assert_close(again, mixed)
    torch.testing.assert_close(same, couplings)


def test_with_placement_noise_the_model_is_given_the_placement_as_a_fit_would_find_it():
    """``trainer.placement_noise=s``: the windows are still mixed by the drawn placement, but
    the model is told it with the errors of a fit: scales off, a joint's weaker sensor missed
    and a sensor it does not reach found (each about s / 2 of the time), its main sensor always
    kept, nothing below the floor of a commissioned C."""
    x = _snapshots()
    graph = harness_graph()
    exact = PlacementPool(graph, x, np.ones(len(x), bool), 8, torch.device("cpu"))
    noisy = PlacementPool(graph, x, np.ones(len(x), bool), 8, torch.device("cpu"), noise=0.4)
    snapshots = torch.arange(8 * 4000).remainder(len(x)).reshape(4000, 8)
    base = torch.from_numpy(graph.transform(x))[snapshots]
    mixed, truth = exact.mix(base, snapshots, torch.Generator().manual_seed(1))
    noisy_mixed, told = noisy.mix(base, snapshots, torch.Generator().manual_seed(1))
    torch.testing.assert_close(noisy_mixed, mixed)  # the data: the true placement
    reached, main = truth > 0, truth == truth.amax(dim=2, keepdim=True)
    weaker = reached & ~main
    assert (told[main] > 0.011).all()
    assert 0.15 < (told[weaker] <= 0.01).float().mean() < 0.25  # missed
    assert 0.15 < (told[~reached] > 0.01).float().mean() < 0.25  # found where it is not
    assert told.min() >= 0.01 - 1e-7
    ratio = torch.log(told[main] / truth[main])
    assert 0.35 < float(ratio.std()) < 0.45  # scales off by exp(0.4 N(0, 1))
    with pytest.raises(ValueError, match="placement_noise"):
        PlacementPool(graph, x, np.ones(len(x), bool), 8, torch.device("cpu"), noise=-0.1)


def test_a_given_coupling_takes_the_place_of_the_learned_one():
    torch.manual_seed(0)
    head = AnomalyResidualHead(hidden=8, num_joints=J, num_sensors=4, scores="energy")
    nodes = torch.randn(3, J + 4, 8)
    c = torch.from_numpy(harness_graph(coupling_seed=4).coupling).clamp_min(0.05)
    given = head(nodes, c.expand(3, -1, -1))
    learned_before = head(nodes)
    assert not torch.allclose(given[0], learned_before[0])
    head.set_coupling(c)
    torch.testing.assert_close(head.coupling(), c)
    for a, b in zip(given, head(nodes), strict=True):
        torch.testing.assert_close(a, b)


def test_refitting_the_coupling_finds_the_placement_that_reconstructs_the_sensors():
    """With a predictor that passes the coupled joints through, healthy sensors that are
    mixtures of the joints' embeddings identify the placement that mixed them."""
    torch.manual_seed(0)
    head = AnomalyResidualHead(hidden=16, num_joints=J, num_sensors=4)
    head.f = nn.Identity()
    truth = harness_graph(coupling_seed=7).coupling
    c_pred = torch.from_numpy(truth / truth.sum(0, keepdims=True))
    joints = torch.randn(256, J, 16)
    nodes = torch.cat([joints, torch.einsum("jm,bjh->bmh", c_pred, joints)], dim=1)
    before, after = reconstruction_estimate(head, nodes, steps=400)
    assert after < 0.1 * before
    assert coupling_correlation(head.coupling().detach().numpy(), truth) > 0.9


def _moving_arm(seed: int, n: int = 4000) -> SimpleNamespace:
    """Healthy snapshots of six joints sweeping at their own rates, each joint's sensor package
    emitting in proportion to its own speed (the drive's emission), plus noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)[:, None] / 20.0
    rate, phase = rng.uniform(0.2, 1.5, J), rng.uniform(0, 2 * np.pi, J)
    x = np.zeros((n, schema.N_NODES, schema.N_FEATURES), np.float32)
    x[:, :J, POS] = np.sin(rate * t + phase)
    x[:, :J, VEL] = rate * np.cos(rate * t + phase)
    gain = np.random.default_rng(99).uniform(0.5, 2.0, (J, 8))  # one drive, one gain: fixed
    speed = np.abs(x[:, :J, VEL])[..., None]
    x[:, J:, S] = gain * (speed + 0.5 * speed**2) + rng.normal(0, 0.05, (n, J, 8))
    return SimpleNamespace(x=x, active=np.zeros(n, bool))


def test_the_motion_fit_finds_the_placement_from_healthy_running():
    """Sensors that mix what the joints' drives emit, as their motion makes them emit it, give
    back the placement that mixed them: the predictors come from another session."""
    corr = []
    for seed in (3, 7):
        world = harness_graph(coupling_seed=seed)
        est = motion_estimate(_moving_arm(1), _moving_arm(2), world)
        assert est.shape == world.coupling.shape and est.min() >= 0.0
        corr.append(coupling_correlation(est, world.coupling))
    assert np.mean(corr) > 0.985  # 0.991 (without the z-scoring's offset per channel: 0.971)


def test_the_fit_drops_joints_that_barely_explain_a_sensor_and_keeps_the_ones_that_do():
    """A sensor mounted to hear joints 1 and 4 (weights 1 and 0.5), with a faint hum of every
    other drive through the structure (0.02) and noise: a plain non-negative fit gives every
    joint weight; pruning leaves exactly joints 1 and 4, at their weights."""
    rng = np.random.default_rng(0)
    packages = rng.normal(size=(2000, J))
    hum = 0.02 * packages[:, [0, 2, 3, 5]].sum(axis=1)
    sensor = packages[:, 1] + 0.5 * packages[:, 4] + hum + 0.3 * rng.normal(size=2000) + 2.0
    offsets = np.ones((2000, 1))
    plain = sparse_mixture(packages, offsets, sensor, prune=0.0)
    assert np.count_nonzero(plain) == J
    pruned = sparse_mixture(packages, offsets, sensor, prune=0.006)
    assert np.flatnonzero(pruned).tolist() == [1, 4]
    np.testing.assert_allclose(pruned[[1, 4]], [1.0, 0.5], atol=0.03)


def _tiny_training(corpus: Path, overrides: list[str]):
    """The train config on the tiny corpus, quiet, without the probe session."""
    return compose_config("train", [
        f"data.train=[{corpus}/train_*]", f"data.evaluate.heldout={corpus}/heldout",
        "data.evaluate.probe=null", "trainer.progress=false", *overrides,
    ])  # fmt: skip


@pytest.fixture(scope="module")
def drawn(tiny_corpus, tmp_path_factory) -> dict:
    """A barely trained self-calibrating model (``+experiment=self_calibrating``: the placement
    told to edges, sensors and head, given as a fit finds it) under four drawn placements
    (harness, W = 8)."""
    root = tmp_path_factory.mktemp("drawn")
    cfg = _tiny_training(tiny_corpus, [
        "+experiment=self_calibrating",
        "window=8", "model.hidden=8", "trainer.epochs=1", "trainer.placements=4",
        "trainer.placement_noise=0.3",
    ])  # fmt: skip
    return {"results": run(cfg, root), "ckpt": root / "best.ckpt", "corpus": tiny_corpus}


def test_a_model_trained_under_drawn_placements_is_given_its_own(drawn):
    assert drawn["results"]["train"]["placements_drawn"] == 4
    ckpt = load_checkpoint(drawn["ckpt"])
    assert {k: ckpt["model_cfg"][k] for k in OPTIONS} == dict.fromkeys(OPTIONS, True)
    c = build(ckpt).anomaly.coupling().detach().numpy()
    np.testing.assert_allclose(c, np.maximum(DEFAULT_C0, 1e-2), rtol=1e-4)


@pytest.fixture(scope="module")
def healthy_arm(tmp_path_factory) -> Path:
    """30 s of the nominal arm's healthy running."""
    root = tmp_path_factory.mktemp("healthy_arm")
    cfg = compose_config("record", ["session.progress=false", "faults=none", "seed=6",
                                    "session.duration_s=30"])  # fmt: skip
    record_session(cfg, root)
    return root


def test_commissioning_refits_the_coupling_to_the_arms_placement(drawn, healthy_arm, tmp_path):
    record = commission(drawn["ckpt"], str(healthy_arm), tmp_path, export=False,
                        placement={"coupling_seed": 3})  # fmt: skip
    ckpt = load_checkpoint(tmp_path / "best.ckpt")
    world = graph_from_checkpoint(ckpt)
    truth = harness_graph(coupling_seed=3).coupling
    np.testing.assert_array_equal(world.coupling, truth)  # the data is mixed where it sits
    refitted = build(ckpt).anomaly.coupling().detach().numpy()
    found = record["placement"]
    assert found["fit"] == "motion"
    np.testing.assert_allclose(refitted, found["coupling"], atol=1e-4)
    reference = load_recordings(sorted(drawn["corpus"].glob("train_*/graphs.jsonl")))
    arm = load_recordings([healthy_arm / "graphs.jsonl"])
    want = np.maximum(motion_estimate(reference, arm, world), 1e-2)  # softplus's floor
    np.testing.assert_allclose(refitted, want, rtol=1e-3, atol=1e-4)
    # the placement found is written as a placement file a model can be trained on
    assert found["file"] == str(tmp_path / "placement.json")
    np.testing.assert_allclose(load_coupling(found["file"]), want, rtol=1e-3, atol=1e-4)
    assert found["coupling_correlation"] == pytest.approx(
        coupling_correlation(refitted, truth), abs=1e-3
    )
    # the sensors are z-scored on this arm's healthy running, as the model was trained
    mu, sd = healthy_sensor_statistics(world, arm.x)
    np.testing.assert_allclose(ckpt["norm_mean"].numpy()[J:, S], mu, rtol=1e-5)
    np.testing.assert_allclose(ckpt["norm_std"].numpy()[J:, S], sd, rtol=1e-5)


def test_a_placement_the_model_cannot_read_is_one_line(drawn, stock_deployed, healthy_arm, capsys):
    bad = {  # another number of sensors; a model without a placement
        "reads 4 sensors": [f"model={drawn['ckpt']}", "placement.coupling_seed=3",
                            "placement.coupling_sensors=6"],
        "no placement to calibrate": [f"model={stock_deployed['ckpt']}",
                                      "placement.coupling_seed=3"],
        "placement_prune must be in [0, 1)": [f"model={drawn['ckpt']}",
                                              "placement.coupling_seed=3", "placement_prune=-1"],
    }  # fmt: skip
    for message, args in bad.items():
        with pytest.raises(SystemExit) as stop:
            commission_main([*args, f"healthy={healthy_arm}", "export=false"])
        assert stop.value.code == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and message in err, err


def test_the_reconstruction_fit_lowers_the_models_reconstruction_error(
    drawn, healthy_arm, tmp_path
):
    record = commission(drawn["ckpt"], str(healthy_arm), tmp_path, export=False,
                        placement={"coupling_seed": 3}, placement_fit="reconstruction")  # fmt: skip
    found = record["placement"]
    assert found["fit"] == "reconstruction"
    assert found["reconstruction_after"] < found["reconstruction_before"]
    refitted = build(load_checkpoint(tmp_path / "best.ckpt")).anomaly.coupling().detach().numpy()
    np.testing.assert_allclose(refitted, found["coupling"], atol=1e-4)


def test_a_commissioned_self_calibrating_model_streams_as_it_scores_windows(
    drawn, healthy_arm, tmp_path
):
    """The placement found reaches the exported model's edges, sensors and head alike: the
    fleet runtime's incremental form (one snapshot a tick) gives the windowed form's
    probabilities on the arm's running."""
    record = commission(drawn["ckpt"], str(healthy_arm), tmp_path, placement={"coupling_seed": 3})
    x = load_recordings([healthy_arm / "graphs.jsonl"]).x
    probs, modes = [], []
    for incremental in (True, False):
        fleet = FleetRuntime(record["onnx"], incremental=incremental)
        modes.append(fleet.mode)
        slots = fleet.register(["a", "b"])
        decided = []
        for t in range(40):
            r = fleet.step(slots, np.full(2, t), np.full(2, 0.05 * (t + 1)), x[[t, t + 100]])
            decided.append(np.where((r.status == DECIDED)[:, None], r.probs, np.nan))
        probs.append(np.array(decided))
    assert modes == ["incremental", "windowed"]
    assert (~np.isnan(probs[0])).sum() > 100
    np.testing.assert_array_equal(np.isnan(probs[0]), np.isnan(probs[1]))
    assert np.nanmax(np.abs(probs[0] - probs[1])) <= 1e-4


def test_training_with_the_motion_fit_sets_the_placement_once_and_never_moves_it(
    tiny_corpus, tmp_path
):
    """``+experiment=unknown_placement`` (issue 69): the trained model's C is the motion
    estimate on the healthy running its training windows cover, set before the first step and
    unchanged by training, and reaches the joint scores and the edges; it reads the drawn
    placement with the right sign (its correlation is positive and recorded with the run)."""
    from robohealth_mj.learn.motion_placement import training_placement
    from robohealth_mj.learn.trainer import prepare

    cfg = _tiny_training(tiny_corpus, [
        "+experiment=unknown_placement",
        "graph.coupling_seed=3", "window=8", "variant=anomaly_residual", "model.hidden=8",
        "trainer.epochs=2",
    ])  # fmt: skip
    results = run(cfg, tmp_path)
    ckpt = load_checkpoint(tmp_path / "best.ckpt")
    assert ckpt["model_cfg"]["coupling_fit"] == "motion"
    assert ckpt["model_cfg"]["anomaly_joint_scores"] and ckpt["model_cfg"]["coupled_edges"]
    trained = build(ckpt).anomaly.coupling().detach().numpy()
    p = prepare(cfg)
    fitted = training_placement(p.rec, p.splits["train"], p.graph)
    np.testing.assert_allclose(trained, np.maximum(fitted, 1e-2), rtol=1e-4, atol=1e-5)
    truth = harness_graph(coupling_seed=3).coupling
    corr = coupling_correlation(trained, truth)
    assert corr > 0.5
    assert results["train"]["coupling_correlation"] == pytest.approx(corr, abs=1e-4)


def test_a_given_placement_is_the_truth_frozen_and_needs_a_harness(tiny_corpus, tmp_path):
    """``model.coupling_fit=given`` (a study's ceiling: the same sensors with the placement
    known): the trained C is the graph's true placement, untouched by training; a graph without
    a placement is one line before any data."""
    from robohealth_mj.learn.trainer import prepare

    cfg = _tiny_training(tiny_corpus, [
        "+experiment=unknown_placement",
        "graph.coupling_seed=3", "window=8", "model.hidden=8", "trainer.epochs=1",
        "model.coupling_fit=given",
    ])  # fmt: skip
    run(cfg, tmp_path)
    trained = build(load_checkpoint(tmp_path / "best.ckpt")).anomaly.coupling().detach().numpy()
    truth = harness_graph(coupling_seed=3).coupling
    np.testing.assert_allclose(trained, np.maximum(truth, 1e-2), rtol=1e-4, atol=1e-5)
    structural = compose_config("train", [
        "data.train=[/nonexistent/train_*]", "model.coupling_fit=given",
    ])  # fmt: skip
    with pytest.raises(ValueError, match=r"^model.coupling_fit=given needs graph=harness"):
        prepare(structural)


def test_a_motion_fit_under_drawn_placements_is_refused_before_any_data():
    """One placement fitted from the data and a placement per window contradict each other."""
    from robohealth_mj.learn.trainer import prepare

    cfg = compose_config("train", [
        "data.train=[/nonexistent/train_*]", "graph=harness", "variant=anomaly_residual",
        "model.coupling_fit=motion", "trainer.placements=4",
    ])  # fmt: skip
    with pytest.raises(ValueError, match=r"coupling_fit=motion .* choose one"):
        prepare(cfg)
