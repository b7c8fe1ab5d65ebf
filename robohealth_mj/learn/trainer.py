"""One training run: data -> run-aware split -> model -> best-validation checkpoint.

One seed controls Python, NumPy, PyTorch (initialisation, batch order, dropout) and the splitter.
"""

from __future__ import annotations

import glob
import math
import random
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch
from hydra.utils import instantiate
from omegaconf import DictConfig, OmegaConf
from tqdm import tqdm

from robohealth_mj import schema
from robohealth_mj.atomic import atomic_write_json
from robohealth_mj.data.arrays import load_recordings, resolve_recordings
from robohealth_mj.data.graphs import GraphSpec, coupling_correlation
from robohealth_mj.data.windows import make_windows, normalisation, run_aware_split
from robohealth_mj.learn.checkpoint import save_checkpoint
from robohealth_mj.learn.data import WindowTensors
from robohealth_mj.learn.loss import training_loss
from robohealth_mj.learn.metrics import compute_metrics
from robohealth_mj.learn.predict import Predictions, predict
from robohealth_mj.models import build_model
from robohealth_mj.version import code_version

CHECKPOINT = "best.ckpt"


def seed_everything(seed: int) -> None:
    random.seed(seed)
    np.random.seed(seed)
    torch.manual_seed(seed)


def pick_device(name: str) -> torch.device:
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(name)


def expand_paths(patterns: list[str] | str) -> list[Path]:
    """Paths, session dirs and glob patterns -> recording files (sorted, each once)."""
    patterns = [patterns] if isinstance(patterns, str) else list(patterns)
    found: list[str] = []
    for pattern in patterns:
        matches = sorted(glob.glob(pattern)) if any(c in pattern for c in "*?[") else [pattern]
        if not matches:
            raise FileNotFoundError(f"no recordings match {pattern!r}")
        found += matches
    return list(dict.fromkeys(resolve_recordings(found)))


def metrics_of(pred: Predictions) -> dict[str, Any]:
    return compute_metrics(
        pred.class_logits.argmax(1),
        pred.joint_logits.argmax(1),
        pred.true_class,
        pred.true_joint,
        pred.active,
        pred.true_severity,
        pred.severity,
    )


def coupling_report(model: torch.nn.Module, graph: GraphSpec) -> dict[str, Any]:
    head = getattr(model, "anomaly", None)
    if head is None:
        return {}
    learned = head.coupling().detach().cpu().numpy()
    out: dict[str, Any] = {"coupling": learned.round(5).tolist()}
    if graph.coupling is not None:
        out["coupling_correlation"] = coupling_correlation(learned, graph.coupling)
    return out


def train_run(cfg: DictConfig, out_dir: Path) -> dict[str, Any]:
    """Train one variant; write ``best.ckpt``, ``train_summary.json`` and TensorBoard logs."""
    from torch.utils.tensorboard import SummaryWriter

    out_dir.mkdir(parents=True, exist_ok=True)
    seed_everything(int(cfg.seed))
    if cfg.trainer.get("threads"):
        torch.set_num_threads(int(cfg.trainer.threads))
    device = pick_device(cfg.trainer.device)
    t = cfg.trainer
    graph: GraphSpec = instantiate(cfg.graph)
    rec = load_recordings(expand_paths(cfg.data.train))
    x = graph.transform(rec.x)
    windows = make_windows(rec, int(cfg.window), cfg.stride)
    splits = run_aware_split(rec, windows, int(cfg.seed))
    mean, std = normalisation(x, splits["train"])
    tensors = WindowTensors(x, rec, mean, std, device)
    model = build_model(
        cfg.model, graph.adjacency, graph.num_joints, schema.N_FEATURES, int(cfg.window)
    ).to(device)
    optimiser = torch.optim.Adam(model.parameters(), lr=t.lr, weight_decay=t.weight_decay)
    writer = SummaryWriter(str(out_dir / "tensorboard"))

    def loss_fn(out, batch):
        return training_loss(
            out, batch, t.joint_loss_weight, t.recon_loss_weight, t.severity_loss_weight
        )

    generator = torch.Generator().manual_seed(int(cfg.seed))
    train_windows = splits["train"]
    per_epoch = (
        len(train_windows)
        if t.max_windows_per_epoch is None
        else min(len(train_windows), int(t.max_windows_per_epoch))
    )
    best_loss, best_epoch, history = math.inf, -1, []
    started = time.perf_counter()
    for epoch in range(1, int(t.epochs) + 1):
        model.train()
        order = torch.randperm(len(train_windows), generator=generator)[:per_epoch].numpy()
        bar = tqdm(
            range(0, per_epoch, int(t.batch_size)),
            desc=f"epoch {epoch}/{t.epochs}",
            leave=False,
            disable=not t.progress,
            dynamic_ncols=True,
        )
        running = 0.0
        for step, i in enumerate(bar, start=1):
            batch = tensors.batch(train_windows, order[i : i + int(t.batch_size)])
            loss, _ = loss_fn(model(batch.x), batch)
            optimiser.zero_grad(set_to_none=True)
            loss.backward()
            optimiser.step()
            running += loss.item()
            if step % 10 == 0:
                bar.set_postfix(loss=f"{running / step:.4f}")
        val = predict(model, tensors, splits["val"], loss_fn=loss_fn)
        val_m = metrics_of(val)
        row = {
            "epoch": epoch,
            "train_loss": running / max(step, 1),
            "val_loss": val.loss,
            "val_accuracy": val_m.get("accuracy"),
            "val_localisation": val_m.get("localisation_accuracy"),
            "val_macro_f1": val_m.get("macro_f1"),
        }
        gamma = (
            getattr(model.adjacency, "gamma", lambda: None)()
            if hasattr(model, "adjacency")
            else None
        )
        if gamma is not None:
            row["gamma"] = float(gamma)
        history.append(row)
        for key, value in row.items():
            if key != "epoch" and value is not None:
                writer.add_scalar(key, value, epoch)
        if t.progress:
            tqdm.write(
                f"epoch {epoch:>3}: loss {row['train_loss']:.4f}  val loss {val.loss:.4f}  "
                f"acc {row['val_accuracy']:.3f}  loc {row['val_localisation']:.3f}"
            )
        if val.loss < best_loss:
            best_loss, best_epoch = val.loss, epoch
            save_checkpoint(
                out_dir / CHECKPOINT,
                model,
                model_cfg=OmegaConf.to_container(cfg.model, resolve=True),
                variant=str(cfg.variant),
                graph=graph,
                window=int(cfg.window),
                mean=mean,
                std=std,
                config=OmegaConf.to_container(cfg, resolve=True),
                code_version=code_version(),
                data_fingerprint=rec.fingerprint(),
                best_epoch=best_epoch,
                extra={
                    "gamma": row.get("gamma"),
                    "split_runs": {
                        k: sorted({rec.run_ids[r] for r in rec.run[w.end]})
                        for k, w in splits.items()
                    },
                },
            )
    writer.close()
    from robohealth_mj.learn.checkpoint import load_checkpoint, model_from_checkpoint

    best = model_from_checkpoint(load_checkpoint(out_dir / CHECKPOINT)).to(device)
    test_m = metrics_of(predict(best, tensors, splits["test"]))
    summary = {
        "variant": str(cfg.variant),
        "window": int(cfg.window),
        "seed": int(cfg.seed),
        "graph": graph.name,
        "best_epoch": best_epoch,
        "epochs": int(t.epochs),
        "gamma": history[best_epoch - 1].get("gamma"),
        "train_seconds": time.perf_counter() - started,
        "windows": {k: len(v) for k, v in splits.items()},
        "split_runs": {
            k: sorted({rec.run_ids[r] for r in rec.run[w.end]}) for k, w in splits.items()
        },
        "data_fingerprint": rec.fingerprint(),
        "history": history,
        "test": test_m,
        **coupling_report(best, graph),
    }
    atomic_write_json(out_dir / "train_summary.json", summary)
    return summary
