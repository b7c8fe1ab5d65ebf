"""One training run: data -> run-aware split -> model -> best-validation checkpoint.

One seed controls Python, NumPy, PyTorch (initialisation, batch order, dropout) and the splitter.
"""

from __future__ import annotations

import json
import math
import random
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from hydra.utils import instantiate
from omegaconf import DictConfig, OmegaConf
from tqdm import tqdm

from robohealth_mj import schema
from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.config import placement_name
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.threads import resolve_threads, use_torch_threads
from robohealth_mj.common.version import code_version
from robohealth_mj.data.arrays import expand_paths, load_recordings
from robohealth_mj.data.graphs import GraphSpec, coupling_correlation
from robohealth_mj.data.windows import (
    label_windows,
    make_windows,
    normalisation,
    run_aware_split,
)
from robohealth_mj.learn.checkpoint import save_checkpoint, training_arms
from robohealth_mj.learn.data import WindowTensors
from robohealth_mj.learn.distill import load_teacher, soft_label_loss
from robohealth_mj.learn.loss import loss_from_config
from robohealth_mj.learn.metrics import metrics_of
from robohealth_mj.learn.motion_placement import training_placement
from robohealth_mj.learn.placements import PlacementPool, given_placement, placement_pool
from robohealth_mj.learn.predict import predict
from robohealth_mj.models import build_model

CHECKPOINT = "best.ckpt"


def seed_everything(seed: int) -> None:
    random.seed(seed)
    np.random.seed(seed)
    torch.manual_seed(seed)


def pick_device(name: str) -> torch.device:
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(name)


def finished_on_current_data(cfg: DictConfig, out_dir: Path) -> bool:
    """A run whose summary and held-out evaluation exist *and* were made on the data the config
    names now (fingerprints agree). A re-recorded corpus keeps its paths and run ids, so the files'
    existence alone would report stale numbers."""
    summary_path, eval_path = out_dir / "train_summary.json", out_dir / "eval_heldout.json"
    if not (summary_path.is_file() and eval_path.is_file()):
        return False
    try:
        summary = json.loads(summary_path.read_text())
        evaluation = json.loads(eval_path.read_text())
        heldout = (cfg.data.evaluate or {}).get("heldout")
        fresh = (
            summary.get("data_fingerprint")
            == load_recordings(
                expand_paths(cfg.data.train), pad=bool(cfg.get("transfer", False))
            ).fingerprint()
        )
        if heldout:
            fresh &= (
                evaluation.get("data_fingerprint")
                == load_recordings(expand_paths(heldout)).fingerprint()
            )
    except (OSError, ValueError, KeyError):
        return False
    return bool(fresh)


def coupling_report(model: torch.nn.Module, graph: GraphSpec) -> dict[str, Any]:
    head = getattr(model, "anomaly", None)
    if head is None:
        return {}
    learned = head.coupling().detach().cpu().numpy()
    out: dict[str, Any] = {"coupling": learned.round(5).tolist()}
    if graph.coupling is not None:
        out["coupling_truth"] = np.asarray(graph.coupling).round(5).tolist()
        out["coupling_correlation"] = coupling_correlation(learned, graph.coupling)
    return out


def validation_score(metrics: dict[str, Any]) -> float:
    """What checkpoint selection and early stopping maximise: the mean of validation accuracy
    and localisation accuracy (both are what a user is promised)."""
    acc = metrics.get("accuracy", float("nan"))
    loc = metrics.get("localisation_accuracy", float("nan"))
    return float(np.nanmean([acc, loc]))


@dataclass
class Prepared:
    """Everything a fitting path needs: data, split, normalisation and the built model."""

    cfg: DictConfig
    graph: GraphSpec
    rec: Any
    splits: dict[str, Any]
    mean: np.ndarray
    std: np.ndarray
    tensors: WindowTensors
    model: torch.nn.Module
    device: torch.device
    pool: PlacementPool | None = None  # training under drawn placements (trainer.placements)


def prepare(cfg: DictConfig) -> Prepared:
    seed_everything(int(cfg.seed))
    use_torch_threads(resolve_threads(cfg.get("threads"), "threads"))
    device = pick_device(cfg.trainer.device)
    graph: GraphSpec = instantiate(cfg.graph)  # a bad config value is named before any data
    sensing = instantiate(cfg.sensing)
    fit = cfg.model.get("coupling_fit")
    if fit in ("motion", "given") and cfg.trainer.get("placements"):
        raise InputError(
            f"model.coupling_fit={fit} sets one placement; trainer.placements gives each window "
            "its own: choose one"
        )
    if fit == "given" and graph.coupling is None:
        raise InputError("model.coupling_fit=given needs graph=harness (a placement to give)")
    files = expand_paths(cfg.data.train)
    check_transfer(cfg, files)
    rec = load_recordings(files, pad=bool(cfg.get("transfer", False)))  # across joint counts
    graph = graph.for_arm(rec.graph).with_sensing(sensing)  # the recordings' arm's graph
    rec = graph.relabel(rec)
    rec = label_windows(rec, int(cfg.window), str(cfg.get("labels", "last")))
    x = graph.transform(rec.x)
    windows = make_windows(rec, int(cfg.window), cfg.stride)
    splits = run_aware_split(rec, windows, int(cfg.seed))
    mean, std = normalisation(x, splits["train"])
    model = build_model(
        cfg.model, graph.adjacency, graph.num_joints, schema.N_FEATURES, int(cfg.window)
    ).to(device)
    head = getattr(model, "anomaly", None)
    if head is not None and head.coupling_fit == "motion":
        head.set_coupling(training_placement(rec, splits["train"], graph))  # frozen from here
    elif head is not None and head.coupling_fit == "given":  # a study's ceiling: the truth
        head.set_coupling(graph.coupling)
    pool = None
    if cfg.trainer.get("placements"):
        pool = placement_pool(
            graph,
            rec,
            splits["train"],
            int(cfg.trainer.placements),
            device,
            float(cfg.trainer.get("placement_noise") or 0.0),
        )
        given_placement(model, graph, pool, mean, std)
    tensors = WindowTensors(x, rec, mean, std, device)
    return Prepared(cfg, graph, rec, splits, mean, std, tensors, model, device, pool)


def prepare_from_checkpoint(ckpt: dict[str, Any]) -> Prepared:
    """A checkpoint's training again: the same data, split and normalisation (its config) and its
    trained weights, for research that refits or probes one part of a model."""
    cfg = OmegaConf.create(ckpt["config"])
    cfg.trainer.progress = False
    p = prepare(cfg)
    p.model.load_state_dict(ckpt["state_dict"])
    return p


def save_prepared(p: Prepared, out_dir: Path, best_epoch: int, gamma: float | None) -> None:
    """``p.model`` as ``out_dir/best.ckpt`` with its config, graph, normalisation and split."""
    cfg = p.cfg
    save_checkpoint(
        out_dir / CHECKPOINT,
        p.model,
        model_cfg=OmegaConf.to_container(cfg.model, resolve=True),
        variant=str(cfg.variant),
        graph=p.graph,
        window=int(cfg.window),
        mean=p.mean,
        std=p.std,
        config=OmegaConf.to_container(cfg, resolve=True),
        code_version=code_version(),
        data_fingerprint=p.rec.fingerprint(),
        best_epoch=best_epoch,
        extra={
            "gamma": gamma,
            "split_runs": split_runs(p),
            "arms": training_arms(expand_paths(cfg.data.train)),
            "transfer": bool(cfg.get("transfer", False)),
        },
    )


def check_transfer(cfg: DictConfig, files: list) -> None:
    """A model trained for transfer must have seen more than one arm (one arm's ratings say
    nothing of how a fault reads on another)."""
    if cfg.get("transfer", False) and len(training_arms(files)) < 2:
        arms = training_arms(files) or ["no named arm"]
        raise InputError(
            f"transfer=true needs training recordings of two arms or more; data.train has "
            f"{', '.join(arms)}"
        )


def split_runs(p: Prepared) -> dict[str, list[str]]:
    return {k: sorted({p.rec.run_ids[r] for r in p.rec.run[w.end]}) for k, w in p.splits.items()}


def gamma_of(model: torch.nn.Module) -> float | None:
    """|γ| of a pose-kernel model, else None."""
    adjacency = getattr(model, "adjacency", None)
    gamma = adjacency.gamma() if adjacency is not None else None
    return None if gamma is None else float(gamma)


def fit_gradient(p: Prepared, out_dir: Path, writer) -> tuple[int, list[dict]]:
    """Mini-batch training with a learning-rate schedule; keeps the checkpoint of the best
    validation score and stops after ``patience`` epochs without improvement."""
    cfg, t, model = p.cfg, p.cfg.trainer, p.model
    optimiser = instantiate(t.optimizer, params=model.parameters())
    train_windows = p.splits["train"]
    per_epoch = (
        len(train_windows)
        if t.max_windows_per_epoch is None
        else min(len(train_windows), int(t.max_windows_per_epoch))
    )
    batch_size = int(t.batch_size)
    steps = math.ceil(per_epoch / batch_size)
    scheduler = (
        instantiate(t.scheduler)(optimiser, total_steps=steps * int(t.epochs))
        if t.get("scheduler")
        else None
    )

    loss_fn = loss_from_config(t)
    teacher = load_teacher(
        t.get("distill"), int(cfg.window), p.graph.name, p.mean, p.std, split_runs(p), p.device
    )
    if teacher is not None and p.pool is not None:
        raise InputError(
            "trainer.distill.teacher with trainer.placements: the teacher was not given the "
            "drawn placements; choose one"
        )
    generator = torch.Generator().manual_seed(int(cfg.seed))
    placements = torch.Generator().manual_seed(int(cfg.seed) + 1)  # the pool's draws
    best_score, best_epoch, history, stale = -math.inf, -1, [], 0
    started = time.perf_counter()
    for epoch in range(1, int(t.epochs) + 1):
        model.train()
        order = torch.randperm(len(train_windows), generator=generator)[:per_epoch].numpy()
        bar = tqdm(
            range(0, per_epoch, batch_size),
            desc=f"epoch {epoch}/{t.epochs}",
            leave=False,
            disable=not t.progress,
            dynamic_ncols=True,
        )
        running = 0.0
        for step, i in enumerate(bar, start=1):
            which = order[i : i + batch_size]
            batch = p.tensors.batch(train_windows, which)
            if p.pool is None:
                out = model(batch.x)
            else:  # each window under a drawn placement, which the model is given
                snapshots = p.tensors.snapshots(train_windows, which)
                out = model(*p.pool.mix(batch.x, snapshots, placements))
            loss, _ = loss_fn(out, batch)
            if teacher is not None:  # (1 - w) hard labels + w the teacher's soft ones
                soft = soft_label_loss(
                    out, teacher.outputs(batch.x), batch.active, teacher.temperature,
                    float(t.joint_loss_weight),
                )  # fmt: skip
                loss = (1.0 - teacher.weight) * loss + teacher.weight * soft
            optimiser.zero_grad(set_to_none=True)
            loss.backward()
            optimiser.step()
            if scheduler is not None:
                scheduler.step()
            running += loss.item()
            if step % 10 == 0:
                bar.set_postfix(loss=f"{running / step:.4f}")
        val = predict(model, p.tensors, p.splits["val"], loss_fn=loss_fn)
        val_m = metrics_of(val)
        row = {
            "epoch": epoch,
            "seconds": time.perf_counter() - started,
            "lr": optimiser.param_groups[0]["lr"],
            "train_loss": running / max(step, 1),
            "val_loss": val.loss,
            "val_accuracy": val_m.get("accuracy"),
            "val_localisation": val_m.get("localisation_accuracy"),
            "val_macro_f1": val_m.get("macro_f1"),
            "val_score": validation_score(val_m),
        }
        gamma = gamma_of(model)
        if gamma is not None:
            row["gamma"] = gamma
        history.append(row)
        for key, value in row.items():
            if key != "epoch" and value is not None:
                writer.add_scalar(key, value, epoch)
        improved = row["val_score"] > best_score
        if t.progress:
            tqdm.write(
                f"epoch {epoch:>3}: loss {row['train_loss']:.4f}  val loss {val.loss:.4f}  "
                f"acc {row['val_accuracy']:.3f}  loc {row['val_localisation']:.3f}"
                f"{'  *' if improved else ''}  ({row['seconds']:.0f} s)"
            )
        if improved:
            best_score, best_epoch, stale = row["val_score"], epoch, 0
            save_prepared(p, out_dir, best_epoch, row.get("gamma"))
        else:
            stale += 1
            if t.patience is not None and stale >= int(t.patience):
                break
    return best_epoch, history


def tree_table(p: Prepared, windows) -> tuple[np.ndarray, ...]:
    """A fitted-in-one-call model's table of ``windows``: (features ``[K, D]``, class ``[K]``,
    joint ``[K]``, severity ``[K]``), built in batches of 4,096 windows."""
    feats, cls, joint, severity = [], [], [], []
    for i in range(0, len(windows), 4096):
        batch = p.tensors.batch(windows, np.arange(i, min(i + 4096, len(windows))))
        feats.append(p.model.features(batch.x))
        cls.append(batch.fault_class.cpu().numpy())
        joint.append(batch.fault_joint.cpu().numpy())
        severity.append(batch.severity.cpu().numpy())
    return tuple(np.concatenate(v) for v in (feats, cls, joint, severity))


def fit_trees(p: Prepared, out_dir: Path, writer) -> tuple[int, list[dict]]:
    """Models fitted in one call (``model.fit``), e.g. the gradient-boosted trees."""
    started = time.perf_counter()
    record = p.model.fit(
        tree_table(p, p.splits["train"]),
        tree_table(p, p.splits["val"]),
        seed=int(p.cfg.seed),
        threads=torch.get_num_threads(),  # the one count prepare() resolved
    )
    val_m = metrics_of(predict(p.model, p.tensors, p.splits["val"]))
    row = {
        "epoch": 1,
        "seconds": time.perf_counter() - started,
        "val_accuracy": val_m.get("accuracy"),
        "val_localisation": val_m.get("localisation_accuracy"),
        "val_macro_f1": val_m.get("macro_f1"),
        "val_score": validation_score(val_m),
        "val_severity_mae_faulted": val_m.get("severity_mae_faulted"),  # None without the head
        "boosting": record,
    }
    for key in ("val_accuracy", "val_localisation", "val_macro_f1", "val_score"):
        writer.add_scalar(key, row[key], 1)
    if p.cfg.trainer.progress:
        tqdm.write(
            f"trees: {record['class']['best_iteration']} + {record['joint']['best_iteration']} "
            f"rounds  val acc {row['val_accuracy']:.3f}  loc {row['val_localisation']:.3f}  "
            f"({row['seconds']:.0f} s)"
        )
    save_prepared(p, out_dir, 1, None)
    return 1, [row]


def train_run(cfg: DictConfig, out_dir: Path) -> dict[str, Any]:
    """Train one variant; write ``best.ckpt``, ``train_summary.json`` and TensorBoard logs."""
    from torch.utils.tensorboard import SummaryWriter

    from robohealth_mj.learn.checkpoint import load_checkpoint, model_from_checkpoint

    out_dir.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    p = prepare(cfg)
    writer = SummaryWriter(str(out_dir / "tensorboard"))
    fit = fit_trees if callable(getattr(p.model, "fit", None)) else fit_gradient
    best_epoch, history = fit(p, out_dir, writer)
    writer.close()
    best = model_from_checkpoint(load_checkpoint(out_dir / CHECKPOINT)).to(p.device)
    test_m = metrics_of(predict(best, p.tensors, p.splits["test"]))
    summary = {
        "variant": str(cfg.variant),
        "window": int(cfg.window),
        "seed": int(cfg.seed),
        "graph": p.graph.name,
        "sensing": p.graph.sensing,
        "placement": placement_name(cfg.graph),
        "placements_drawn": len(p.pool.couplings) if p.pool is not None else 0,
        "anomaly_scores": cfg.model.get("anomaly_scores"),
        "severity_head": bool(cfg.model.get("severity_head", False)),
        "device": str(p.device),
        "threads": torch.get_num_threads(),
        "best_epoch": best_epoch,
        "epochs": len(history),
        "gamma": history[best_epoch - 1].get("gamma"),
        "train_seconds": history[-1]["seconds"],
        "seconds_to_best": history[best_epoch - 1]["seconds"],
        "wall_seconds": time.perf_counter() - started,
        "windows": {k: len(v) for k, v in p.splits.items()},
        "split_runs": split_runs(p),
        "data_fingerprint": p.rec.fingerprint(),
        "history": history,
        "test": test_m,
        **coupling_report(best, p.graph),
    }
    atomic_write_json(out_dir / "train_summary.json", summary)
    return summary
