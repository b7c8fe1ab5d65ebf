"""Held-out and probe accuracy / localisation of exported models, run through onnxruntime.

The float forms score as their checkpoints do (export's parity check holds them to 1e-4); the
int8 forms differ, so every row here comes from the ONNX file itself, on every window the
checkpoint's own evaluation scores (the same recordings, windows and labels).

    python studies/cost_frontier/score.py --out results/scores.json MODEL.onnx=CKPT ... \
        --data val=val heldout=outputs/corpus/standard/heldout_seed900 probe=...
"""

from __future__ import annotations

import argparse
import json
import re
from dataclasses import fields, replace
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.data.arrays import expand_paths, single_arm
from robohealth_mj.data.relative import to_raw
from robohealth_mj.data.windows import target_joint_moved
from robohealth_mj.learn.checkpoint import load_checkpoint
from robohealth_mj.learn.evaluation import Scored, score_checkpoint
from robohealth_mj.learn.metrics import metrics_of

BATCH = 512


def validation_files(ckpt: dict) -> list[str]:
    """The training sessions that hold the checkpoint's validation runs (a session's runs are
    ``<arm>-s<seed>-…``, and its directory ends in ``seed<seed>``): scoring only them is the
    same as scoring every training session and keeping the validation windows, and cheaper."""
    seeds = {re.search(r"-s(\d+)-", run).group(1) for run in ckpt["split_runs"]["val"]}
    files = expand_paths(ckpt["config"]["data"]["train"])
    session = [re.search(r"seed(\d+)$", Path(f).parent.name) for f in files]
    return [str(f) for f, m in zip(files, session, strict=True) if m and m.group(1) in seeds]


def validation_only(scored: Scored) -> Scored:
    """``scored`` cut to the windows that end in its checkpoint's validation runs."""
    runs = list((scored.ckpt.get("split_runs") or {}).get("val", []))
    keep = np.isin(np.asarray(scored.rec.run_ids)[scored.rec.run[scored.windows.end]], runs)
    p = scored.predictions
    cut = {f.name: getattr(p, f.name) for f in fields(p)}
    cut = {k: v[keep] if isinstance(v, np.ndarray) else v for k, v in cut.items()}
    return replace(scored, windows=scored.windows.subset(keep), predictions=replace(p, **cut))


def onnx_outputs(model: str, raw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The windowed graph's class and joint logits on raw windows ``[K, W, N, F]``."""
    import onnxruntime as ort

    options = ort.SessionOptions()
    options.intra_op_num_threads = 1
    session = ort.InferenceSession(model, options, providers=["CPUExecutionProvider"])
    parts = [session.run(None, {"x": raw[i : i + BATCH]}) for i in range(0, len(raw), BATCH)]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def score(model: str, ckpt: str, data: str) -> dict:
    """``model``'s metrics on ``data``, windows and labels as ``ckpt``'s evaluation makes them;
    ``data="val"``: the windows of the checkpoint's validation runs of its training data (what
    a choice between models may be made on)."""
    validation = data == "val"
    if validation:
        data = validation_files(load_checkpoint(ckpt))
    scored = score_checkpoint(ckpt, data, device="cpu")
    if validation:
        scored = validation_only(scored)
    rec, windows = scored.rec, scored.windows
    arm = single_arm(scored.files, None)  # the arm the recordings come from, as export reads it
    idx = windows.start[:, None] + np.arange(windows.window)
    class_logits, joint_logits = [], []
    for i in range(0, len(idx), 4 * BATCH):  # raw windows a few thousand at a time
        raw = to_raw(rec.x[idx[i : i + 4 * BATCH]], arm).astype(np.float32)
        c, j = onnx_outputs(model, raw)
        class_logits.append(c)
        joint_logits.append(j)
    predictions = replace(
        scored.predictions,
        class_logits=np.concatenate(class_logits),
        joint_logits=np.concatenate(joint_logits),
    )
    torch_acc = metrics_of(scored.predictions)["accuracy"]
    metrics = metrics_of(predictions, target_joint_moved(rec, windows))
    return {"model": model, "checkpoint": ckpt, "data": data, "checkpoint_accuracy": torch_acc,
            "metrics": metrics}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="+", help="MODEL.onnx=CHECKPOINT pairs")
    parser.add_argument(
        "--data", nargs="+", required=True,
        help="NAME=PATH recordings; val=val: the checkpoint's own validation runs",
    )  # fmt: skip
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    out = Path(args.out)
    rows = json.loads(out.read_text()) if out.is_file() else {}
    for pair in args.models:
        model, ckpt = pair.split("=", 1)
        for named in args.data:
            name, path = named.split("=", 1)
            key = f"{model}::{name}"
            if key in rows:
                continue
            rows[key] = score(model, ckpt, path)
            m = rows[key]["metrics"]
            print(f"{model} on {name}: accuracy {m['accuracy']:.4f}  localisation "
                  f"{m['localisation_accuracy']:.4f}", flush=True)  # fmt: skip
            atomic_write_json(out, rows)


if __name__ == "__main__":
    main()
