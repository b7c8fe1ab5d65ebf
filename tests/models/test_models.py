"""The nine network variants on both backbones: shapes, gradients, the mechanisms' defining
properties, ONNX parity."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from omegaconf import OmegaConf

from robohealth_mj import schema
from robohealth_mj.common.config import compose_config
from robohealth_mj.common.resources import conf_dir
from robohealth_mj.data.graphs import harness_graph
from robohealth_mj.models import NETWORK_VARIANTS, build_model
from robohealth_mj.models import VARIANTS as ALL_VARIANTS
from robohealth_mj.models.backbone import ThesisBackbone, WindowBackbone
from robohealth_mj.models.onnx import export_onnx, onnx_parity

F = schema.N_FEATURES

ROOT = conf_dir()
CONF = ROOT / "variant"
VARIANTS = sorted(p.stem for p in CONF.glob("*.yaml") if p.stem != "gbdt")
HIDDEN = 16  # small, so the suite stays fast


def _build(
    name: str,
    window: int = 8,
    adjacency=None,
    num_joints: int = 6,
    backbone: str = "window",
    **kw,
):
    torch.manual_seed(0)
    cfg = OmegaConf.merge(
        OmegaConf.load(CONF / f"{name}.yaml"),
        OmegaConf.load(ROOT / "backbone" / f"{backbone}.yaml"),
    )
    cfg.hidden = HIDDEN
    for key, value in kw.items():
        cfg[key] = value
    if "heads" in cfg:
        cfg.heads = 2
    adj = schema.adjacency() if adjacency is None else adjacency
    return build_model(cfg, adj, num_joints, schema.N_FEATURES, window)


def test_all_nine_networks_and_the_baseline_have_configs():
    assert len(VARIANTS) == 9
    assert sorted(NETWORK_VARIANTS) == VARIANTS
    assert ALL_VARIANTS[0] == "gbdt" and (CONF / "gbdt.yaml").is_file()


SHAPE_CASES = [("window", w) for w in (8, 16, 32, 48)] + [("thesis", w) for w in (8, 32)]


@pytest.mark.parametrize("name", VARIANTS)
@pytest.mark.parametrize(("backbone", "window"), SHAPE_CASES)
def test_output_shapes(name, window, backbone):
    model = _build(name, window, backbone=backbone).eval()
    for batch in (1, 128):
        with torch.no_grad():
            out = model(torch.randn(batch, window, 12, F))
        assert out["class_logits"].shape == (batch, 7)
        assert out["joint_logits"].shape == (batch, 6)  # joints only: a sensor can never win
        if "recon_energy" in out:
            assert out["recon_energy"].shape == (batch, 6)
        if "gamma" in out:
            assert out["gamma"].shape == ()


@pytest.mark.parametrize("backbone", ["window", "thesis"])
@pytest.mark.parametrize("name", VARIANTS)
def test_gradients_reach_every_parameter(name, backbone):
    model = _build(name, severity_head=True, backbone=backbone).train()
    out = model(torch.randn(4, 8, 12, F))
    loss = sum(v.float().sum() for v in out.values())
    loss.backward()
    missing = [n for n, p in model.named_parameters() if p.grad is None or not p.grad.abs().sum()]
    assert not missing, missing
    assert out["severity"].shape == (4,)
    assert torch.all((out["severity"] >= 0) & (out["severity"] <= 1))


def test_the_default_backbone_is_the_window_one_and_thesis_rebuilds_the_thesis_model():
    """``backbone=thesis`` composes the thesis's per-snapshot GCN + GRU + attention."""

    def composed(*overrides, features=schema.N_FEATURES):
        cfg = compose_config("train", ["variant=stgnn_fixed", *overrides])
        return build_model(cfg.model, schema.adjacency(), 6, features, 16)

    window = composed()
    assert isinstance(window.backbone, WindowBackbone) and window.classifier.max_pool
    thesis = composed("backbone=thesis")
    assert isinstance(thesis.backbone, ThesisBackbone) and not thesis.classifier.max_pool
    assert isinstance(thesis.backbone.gru, torch.nn.GRU)
    assert thesis.backbone.attention is not None
    # the thesis model's size, on the thesis's 9 input features (schema 1.0)
    thesis_inputs = composed("backbone=thesis", features=9)
    assert sum(p.numel() for p in thesis_inputs.parameters()) == 80_584


@pytest.mark.parametrize("backbone", ["window", "thesis"])
def test_mlp_encodes_each_node_on_its_own(backbone):
    model = _build("mlp", backbone=backbone).eval()
    x = torch.randn(2, 8, 12, F)
    changed = x.clone()
    changed[:, :, 4] += torch.randn(2, 8, F)
    with torch.no_grad():
        a, b = model.node_embeddings(x), model.node_embeddings(changed)
    others = [k for k in range(12) if k != 4]
    torch.testing.assert_close(a[:, others], b[:, others], rtol=0, atol=0)
    assert not torch.allclose(a[:, 4], b[:, 4])


@pytest.mark.parametrize("name", ["stgnn_fixed_pose", "stgnn_pose_cond", "pose_anomaly"])
def test_gamma_zero_recovers_the_unconditioned_graph(name):
    model = _build(name).eval()
    x = torch.randn(3, 8, 12, F)
    with torch.no_grad():
        model.adjacency.pose.gamma.zero_()
        gated = model(x)
        model.adjacency.pose = None
        plain = model(x)
    for key in ("class_logits", "joint_logits"):
        torch.testing.assert_close(gated[key], plain[key], rtol=0, atol=1e-6)


def test_pose_kernel_gates_backbone_edges_by_pose_difference():
    model = _build("stgnn_fixed_pose").eval()
    positions = torch.zeros(1, 12)
    positions[0, 3] = 1.0  # joint 3 far from its neighbours in pose
    with torch.no_grad():
        adj = model.learned_adjacency(positions)[0]
    assert float(adj[2, 3]) == pytest.approx(np.exp(-1.0), rel=1e-5)
    assert float(adj[1, 2]) == 1.0 and float(adj[0, 5]) == 0.0


@pytest.mark.parametrize("name", ["stgnn_learnable", "stgnn_pose_cond"])
def test_learned_adjacency_starts_within_0_02_of_the_structural_graph(name):
    model = _build(name).eval()
    positions = torch.zeros(2, 12)  # equal poses: the kernel is 1 on every edge
    with torch.no_grad():
        learned = model.learned_adjacency(positions)
    structural = torch.as_tensor(schema.adjacency())
    assert (learned - structural).abs().max() <= 0.02


def test_coupling_normalisations_sum_to_one_along_their_axes():
    head = _build("anomaly_residual").anomaly
    with torch.no_grad():
        head.coupling_logits.normal_(0.0, 2.0)
    c_pred, c_scat = head.normalisations()
    torch.testing.assert_close(c_pred.sum(dim=0), torch.ones(6))  # over joints, per sensor
    torch.testing.assert_close(c_scat.sum(dim=1), torch.ones(6))  # over sensors, per joint
    assert torch.all(head.coupling() >= 0)
    fresh = _build("anomaly_residual").anomaly.coupling()
    assert (fresh.max() - fresh.min()) < 0.05  # near-uniform, no structural prior


@pytest.mark.parametrize("name", ["anomaly_residual", "pose_anomaly", "stgnn_fixed", "mlp"])
def test_four_sensors_mixing_six_joints(name):
    """The unknown-placement harness: 6 joints + 4 sensors, dense bipartite joint-sensor edges."""
    adj = np.zeros((10, 10), dtype=np.float32)
    for j in range(5):
        adj[j, j + 1] = adj[j + 1, j] = 1.0
    adj[:6, 6:] = adj[6:, :6] = 1.0
    model = _build(name, adjacency=adj).eval()
    with torch.no_grad():
        out = model(torch.randn(5, 8, 10, F))
    assert out["joint_logits"].shape == (5, 6) and out["class_logits"].shape == (5, 7)
    if hasattr(model, "anomaly") and model.anomaly is not None:
        assert model.anomaly.coupling().shape == (6, 4)


def test_bad_graph_is_a_clear_error():
    with pytest.raises(ValueError, match="square"):
        _build("stgnn_fixed", adjacency=np.zeros((12, 11)))
    with pytest.raises(ValueError, match="num_joints"):
        _build("stgnn_fixed", num_joints=13)
    with pytest.raises(ValueError, match="no sensor nodes"):  # a graph of joints alone
        _build("anomaly_residual", num_joints=12)


@pytest.mark.parametrize("name", VARIANTS)
def test_onnx_export_matches_pytorch_with_a_dynamic_batch(name, tmp_path):
    model = _build(name, window=16, severity_head=(name == "anomaly_residual")).eval()
    with torch.no_grad():  # non-trivial node embeddings, so parity covers them
        model.backbone.encoder.node.normal_()
    path = tmp_path / f"{name}.onnx"
    names = export_onnx(model, torch.randn(2, 16, 12, F), path)
    assert names[:2] == ["class_logits", "joint_logits"]
    for batch in (1, 7):
        assert onnx_parity(model, path, torch.randn(batch, 16, 12, F)) < 1e-4


def test_gbdt_reads_only_the_channels_it_is_given():
    """Channel ablations: the trees' features come from the named channels only."""
    from robohealth_mj.models.gbdt import GradientBoostedTrees

    adj = torch.as_tensor(schema.adjacency())
    x = torch.randn(3, 8, 12, F)
    every = GradientBoostedTrees(adj, 6, F, 8).features(x)
    two = GradientBoostedTrees(adj, 6, F, 8, channels=["vib", "pos_error"]).features(x)
    assert every.shape == (3, 12 * (F - 2) * 7) and two.shape == (3, 12 * 2 * 7)
    x[..., schema.feature_index("effort")] += 5.0  # a channel it does not read
    again = GradientBoostedTrees(adj, 6, F, 8, channels=["vib", "pos_error"]).features(x)
    np.testing.assert_array_equal(two, again)
    with pytest.raises(ValueError, match="unknown"):
        GradientBoostedTrees(adj, 6, F, 8, channels=["torque"])


def test_gbdt_severity_objective_l1_predicts_the_median_level():
    """Where windows cannot tell two severities apart, squared error predicts their mean (a level
    no fault has) and absolute error the median level, which is what MAE scores."""
    from robohealth_mj.models.gbdt import GradientBoostedTrees

    rng = np.random.default_rng(0)
    n = 600
    feats = rng.normal(size=(n, 4)).astype(np.float32)
    group = (feats[:, 0] > 0).astype(int)  # what the windows show: one of two groups
    cls, joint = 1 + group, group  # every window faulted
    # group 0: severity 0.3 twice as often as 0.9 (median 0.3, mean 0.5); group 1: always 0.6
    severity = np.where(group == 1, 0.6, rng.choice([0.3, 0.3, 0.9], size=n)).astype(np.float32)
    split = n * 2 // 3
    data = (feats, cls, joint, severity)
    train = tuple(a[:split] for a in data)
    val = tuple(a[split:] for a in data)
    adj = torch.as_tensor(schema.adjacency())
    # small trees on large leaves: the two groups are all there is to learn
    kw = {"severity": True, "rounds": 60, "num_leaves": 4, "min_child_samples": 50,
          "feature_fraction": 1.0}  # fmt: skip
    predicted, fitted = {}, {}
    for objective in ("regression", "regression_l1"):
        trees = GradientBoostedTrees(adj, 6, F, 8, severity_objective=objective, **kw)
        trees.fit(train, val, seed=0, threads=1)
        predicted[objective] = trees._booster("severity").predict(feats[split:])
        fitted[objective] = trees
    # refitting one head (studies/wear/severity_objective.py) keeps the others and equals
    # a model trained with that objective from the start
    refit, classes = fitted["regression"], fitted["regression"].class_booster.clone()
    refit.severity_objective = "regression_l1"
    refit.fit(train, val, seed=0, threads=1, only=("severity",))
    assert torch.equal(refit.class_booster, classes)
    assert torch.equal(refit.severity_booster, fitted["regression_l1"].severity_booster)
    low = group[split:] == 0
    assert abs(np.median(predicted["regression"][low]) - 0.5) < 0.08
    assert abs(np.median(predicted["regression_l1"][low]) - 0.3) < 0.05
    mae = {k: np.abs(v - severity[split:]).mean() for k, v in predicted.items()}
    assert mae["regression_l1"] < mae["regression"]
    with pytest.raises(ValueError, match=r"model\.severity_objective: 'l3'"):
        GradientBoostedTrees(adj, 6, F, 8, severity_objective="l3")


def _head_with(scores: str, coupling: np.ndarray, seed: int = 0):
    """An anomaly head whose coupling is ``coupling`` and whose predictor ``f`` outputs zero, so
    each sensor's residual is its own embedding."""
    import torch

    from robohealth_mj.models.heads import AnomalyResidualHead

    torch.manual_seed(seed)
    head = AnomalyResidualHead(8, *coupling.shape, scores=scores)
    with torch.no_grad():
        c = torch.as_tensor(coupling, dtype=torch.float32)
        head.coupling_logits.copy_(torch.log(torch.expm1(c)))  # softplus^-1
        for p in head.f.parameters():
            p.zero_()
    return head


def _localised(head, sensor: int) -> int:
    """The joint the head blames when only ``sensor`` deviates."""
    import torch

    nodes = torch.zeros(1, head.num_joints + head.num_sensors, 8)
    nodes[0, head.num_joints + sensor] = 3.0
    logits, _ = head(nodes)
    return int(logits.argmax())


def test_energy_scores_pin_the_coupling_s_sign_where_signed_scores_do_not():
    """When one sensor deviates, the joint coupled to it most is to blame. An inverted coupling
    (``max - C``) blames the joint coupled least. A signed score absorbs the inversion (negate
    ``g`` and the inverted C localises as well as C0 did); an energy score cannot, whatever its
    weights: a flipped coupling no longer scores the same."""
    import torch

    from robohealth_mj.data.graphs import DEFAULT_C0

    c0 = DEFAULT_C0 + 0.05
    inverted = c0.max() + 0.05 - c0
    sensor = 1
    culprit = int(c0[:, sensor].argmax())
    assert int(inverted[:, sensor].argmax()) != culprit
    signed = _head_with("signed", c0)
    if _localised(signed, sensor) != culprit:  # this g scores the deviation low: flip it
        with torch.no_grad():
            signed.g[-1].weight.neg_()
            signed.g[-1].bias.neg_()
    assert _localised(signed, sensor) == culprit
    flipped = _head_with("signed", inverted)
    flipped.g.load_state_dict(signed.g.state_dict())
    with torch.no_grad():
        flipped.g[-1].weight.neg_()
        flipped.g[-1].bias.neg_()
    assert _localised(flipped, sensor) == culprit  # the sign is not identified
    for seed in range(20):
        assert _localised(_head_with("energy", c0, seed), sensor) == culprit
        assert _localised(_head_with("energy", inverted, seed), sensor) != culprit
    with pytest.raises(ValueError, match="anomaly_scores must be one of"):
        _head_with("absolute", c0)


def _pool_model(**options):
    """An ``anomaly_residual`` on the harness graph (6 joints, 4 sensors) with the pool-model
    options ``options`` (coupled_edges, anomaly_joint_scores, placement_embedding)."""
    graph = harness_graph(coupling_seed=3)
    adjacency = graph.adjacency
    model = _build("anomaly_residual", adjacency=adjacency, anomaly_scores="energy", **options)
    model.anomaly.set_coupling(graph.coupling)
    return model.eval(), graph.coupling


def test_coupled_edges_are_the_placement_and_a_refitted_coupling_reaches_message_passing():
    """Dense harness edges tell message passing nothing of the placement, so the class logits do
    not depend on C; coupled edges are C itself, so a C refitted by commissioning changes what
    every node hears, the rest of the model untouched."""
    x = torch.randn(4, 8, 10, F)
    other = harness_graph(coupling_seed=7).coupling
    for coupled in (False, True):
        model, c = _pool_model(coupled_edges=coupled)
        edges = model.edges(x[:, -1, :, schema.feature_index("pos")])
        with torch.no_grad():
            before = model(x)["class_logits"]
            model.anomaly.set_coupling(other)
            after = model(x)["class_logits"]
        if coupled:
            np.testing.assert_allclose(edges[0, :6, 6:].detach(), np.maximum(c, 1e-2), rtol=1e-5)
            np.testing.assert_allclose(edges[0, 6:, :6].detach(), np.maximum(c, 1e-2).T, rtol=1e-5)
            assert (after - before).abs().max() > 1e-3
        else:
            assert (edges[0, :6, 6:] == 1.0).all()
            torch.testing.assert_close(after, before)
    with pytest.raises(Exception, match="need the coupling head"):  # Hydra wraps the InputError
        _build("stgnn_fixed", coupled_edges=True)


def test_joint_scores_break_the_tie_of_joints_coupled_alike():
    """Two joints with the same row of C get the same scattered score whatever the sensors
    say; a per-joint score from each joint's own embedding tells them apart."""
    c = harness_graph(coupling_seed=3).coupling.copy()
    c[1] = c[0]
    nodes = torch.randn(5, 10, HIDDEN)
    for joint_scores in (False, True):
        model, _ = _pool_model(anomaly_joint_scores=joint_scores)
        model.anomaly.set_coupling(c)
        with torch.no_grad():
            logits, _ = model.anomaly(nodes)
        gap = (logits[:, 0] - logits[:, 1]).abs().max()
        assert (gap > 1e-3) if joint_scores else (gap < 1e-5)


def test_each_sensor_is_told_the_joints_it_hears():
    """With the placement embedding a sensor's node embedding moves when its column of C does,
    and nothing else moves."""
    model, c = _pool_model(placement_embedding=True)
    skip = torch.randn(3, 10, HIDDEN)
    moved = c.copy()
    moved[:, 2] = moved[::-1, 2]  # sensor 2 now hears other joints
    with torch.no_grad():
        a = model.placed(skip, torch.as_tensor(c).expand(3, -1, -1))
        b = model.placed(skip, torch.as_tensor(moved).expand(3, -1, -1))
    changed = (a - b).abs().amax(dim=(0, 2))
    assert changed[8] > 1e-3
    assert changed[[0, 1, 2, 3, 4, 5, 6, 7, 9]].max() == 0.0
    torch.testing.assert_close(a[:, :6], skip[:, :6])


def test_a_pool_model_with_every_option_exports_to_onnx_with_its_placement(tmp_path):
    model, _ = _pool_model(coupled_edges=True, anomaly_joint_scores=True, placement_embedding=True)
    with torch.no_grad():
        model.backbone.encoder.node.normal_()
    path = tmp_path / "pool.onnx"
    export_onnx(model, torch.randn(2, 16, 10, F), path)
    for batch in (1, 5):
        assert onnx_parity(model, path, torch.randn(batch, 16, 10, F)) < 1e-4


def test_a_motion_fitted_coupling_is_frozen_whatever_the_losses_reward():
    """``coupling_fit=motion``: C is set before training and no loss moves it, even labels that
    blame, in every window, the joint coupled *least* (labels that reward an inverted C); under
    ``losses`` the same steps move it. An unknown fit is one line."""
    from robohealth_mj.learn.data import WindowBatch
    from robohealth_mj.learn.loss import training_loss
    from robohealth_mj.models.heads import AnomalyResidualHead

    graph = harness_graph(coupling_seed=3)
    n = 16
    healthy = torch.arange(n) % 2 == 0
    least = torch.as_tensor(graph.coupling.sum(axis=1).argmin()).repeat(n)
    batch = WindowBatch(
        x=torch.randn(n, 8, 10, F),
        fault_class=torch.where(healthy, 0, 1),
        fault_joint=torch.where(healthy, -1, least),
        active=~healthy,
        severity=torch.zeros(n),
    )
    for fit, moves in (("motion", False), ("losses", True)):
        model = _build(
            "anomaly_residual", adjacency=graph.adjacency, coupling_fit=fit, coupled_edges=True
        ).train()
        model.anomaly.set_coupling(graph.coupling)
        before = model.anomaly.coupling().detach().clone()
        optimiser = torch.optim.AdamW(model.parameters(), lr=0.05, weight_decay=0.01)
        for _ in range(5):
            optimiser.zero_grad()
            training_loss(model(batch.x), batch, 5.0, 1.0, 0.0)[0].backward()
            optimiser.step()
        moved = not torch.equal(model.anomaly.coupling().detach(), before)
        assert moved == moves, fit
    with pytest.raises(ValueError, match="coupling_fit must be one of"):
        AnomalyResidualHead(8, 6, 4, coupling_fit="inputs")
