"""A trial of placement self-calibration (not a feature): refit a harness model's learned
coupling C on healthy running of an unseen placement, everything else frozen, and see whether C
and localisation come back. Retrofit sensing (where placement matters), W = 32, seed 42.

    .venv/bin/python studies/stock_arm/recouple_trial.py \\
        > studies/stock_arm/results/recouple_trial.txt

Model A: trained on the default placement C0 (4 sensors); placement B: drawn from seed 2 (4
sensors); healthy data: ten healthy minutes of the nominal arm (seed 940, faults=none).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import torch

from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.windows import make_windows
from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checkpoint
from robohealth_mj.learn.checkpoint import model_from_checkpoint as build
from robohealth_mj.learn.data import WindowTensors
from robohealth_mj.learn.metrics import metrics_of
from robohealth_mj.learn.predict import predict

RUNS = "outputs/thesis_physics/harness/retrofit"
A = f"{RUNS}/C0/anomaly_residual/w32/seed42/best.ckpt"
B = f"{RUNS}/seed2_m4/anomaly_residual/w32/seed42/best.ckpt"
CORPUS = "outputs/corpus/deconf"
torch.set_num_threads(1)
ck, cb = load_checkpoint(A), load_checkpoint(B)
g_a, g_b = graph_from_checkpoint(ck), graph_from_checkpoint(cb)
world_b = replace(g_a, coupling=g_b.coupling)  # model A's graph, placement B's sensors
held = g_a.relabel(load_recordings([f"{CORPUS}/heldout_seed900/graphs.jsonl"]))
healthy = load_recordings([f"{CORPUS}/healthy_nominal_seed940/graphs.jsonl"])
W = int(ck["window"])
MEAN, STD = ck["norm_mean"].numpy(), ck["norm_std"].numpy()


def scores(model, graph, mean=MEAN, std=STD) -> str:
    t = WindowTensors(graph.transform(held.x), held, mean, std, torch.device("cpu"))
    m = metrics_of(predict(model, t, make_windows(held, W)))
    return f"{m['accuracy']:.3f} / {m['localisation_accuracy']:.3f}"


def corr(c: np.ndarray) -> float:
    return float(np.corrcoef(c.ravel(), g_b.coupling.ravel())[0, 1])


def recouple(objective: str, steps: int = 400, lr: float = 0.05, sensor_nodes: bool = False):
    """C refitted (and, with ``sensor_nodes``, the sensor nodes' learned embeddings too)."""
    model = build(ck)
    for p in model.parameters():
        p.requires_grad_(False)
    head = model.anomaly
    head.coupling_logits.requires_grad_(True)
    torch.manual_seed(0)
    with torch.no_grad():
        head.coupling_logits.normal_(0.0, head.init_noise)
    params = [head.coupling_logits]
    node = model.backbone.encoder.node
    if sensor_nodes:  # only the sensors' rows move: the joints' embeddings stay as trained
        node.requires_grad_(True)
        keep = torch.zeros_like(node)
        keep[head.num_joints :] = 1.0
        node.register_hook(lambda grad: grad * keep)
        params.append(node)
    t = WindowTensors(world_b.transform(healthy.x), healthy, MEAN, STD, torch.device("cpu"))
    w = make_windows(healthy, W)
    opt = torch.optim.Adam(params, lr=lr)
    gen = torch.Generator().manual_seed(0)
    model.eval()
    for _ in range(steps):
        b = t.batch(w, torch.randint(0, len(w), (256,), generator=gen).numpy())
        if objective == "training's recon term":
            loss = model(b.x)["recon_energy"].sum(-1).mean()
        else:  # every sensor's prediction error, unweighted by the coupling
            _, (_, temporal, _) = model._features(b.x)
            c_pred, _ = head.normalisations()
            j = head.num_joints
            pred = head.f(torch.einsum("jm,bjh->bmh", c_pred, temporal[:, :j]))
            loss = (temporal[:, j:] - pred).pow(2).mean()
        opt.zero_grad()
        loss.backward()
        opt.step()
    return model, corr(head.coupling().detach().numpy())


print("| model | data placement | C's corr. with B's | accuracy / localisation |")
print("|---|---|---|---|")
learned_a = build(ck).anomaly.coupling().detach().numpy()
print(f"| A as trained | A | — | {scores(build(ck), g_a)} |")
print(f"| A as trained | B | {corr(learned_a):.3f} | {scores(build(ck), world_b)} |")
b_norm = (cb["norm_mean"].numpy(), cb["norm_std"].numpy())
print(f"| B (trained on B) | B | — | {scores(build(cb), g_b, *b_norm)} |")
for objective in ("training's recon term", "unweighted reconstruction"):
    model, r = recouple(objective)
    print(f"| A, C refitted ({objective}) | B | {r:.3f} | {scores(model, world_b)} |")
model, r = recouple("unweighted reconstruction", sensor_nodes=True)
print(f"| A, C and sensor-node embeddings refitted (unweighted) | B | {r:.3f} | "
      f"{scores(model, world_b)} |")  # fmt: skip
