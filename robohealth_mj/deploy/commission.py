"""Commissioning a model on a new arm: minutes of its healthy running, no labels.

What is arm-specific is refitted and the rest kept: the healthy baseline of the residual
channels (its constant term is the normalisation's offset; see :mod:`robohealth_mj.data.baseline`)
is fitted on the new arm and on the model's own training arms (their healthy ticks), and the
difference rides with the graph into the checkpoint and the exported model's input stage. The
report says how many healthy minutes the baseline needed to settle. A harness model's coupling
``C`` is refitted to where the arm's sensors sit (placement self-calibration), and last the
healthy operating point is matched (:mod:`robohealth_mj.deploy.operating_point`). Where the
model reads the torque residual, the contact watch's thresholds are fitted on the same healthy
running (:mod:`robohealth_mj.runtime.contact`).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.errors import InputError
from robohealth_mj.data import baseline
from robohealth_mj.data.arrays import Recording, expand_paths, single_arm
from robohealth_mj.data.graphs import GraphSpec, harness_graph
from robohealth_mj.data.relative import to_raw
from robohealth_mj.data.sensing import load_profile
from robohealth_mj.deploy.export import export_checkpoint, file_fingerprint
from robohealth_mj.deploy.operating_point import Reading, check_recipe, match_operating_point
from robohealth_mj.deploy.recouple import recouple
from robohealth_mj.deploy.renormalise import MATCHES, healthy_moments, match_healthy
from robohealth_mj.learn.checkpoint import (
    graph_from_checkpoint,
    load_checked,
    load_checkpoint,
    model_from_checkpoint,
    save_checkpoint,
)
from robohealth_mj.learn.trainer import CHECKPOINT
from robohealth_mj.runtime.contact import commission_thresholds

PLACEMENT = "placement.json"  # the placement self-calibration found, [6, M]
MINUTES = (0.5, 1.0, 2.0, 3.0, 5.0, 7.5, 10.0, 15.0, 20.0)
SETTLED = 0.1  # a baseline has settled when it moves the residuals within 10 % of the final fit


def _healthy(ckpt: dict, paths: list[str] | str, what: str, arm: str | None = None) -> Recording:
    files = expand_paths(paths)
    rec = load_checked(ckpt, files, arm)
    if what == "healthy" and rec.active.any():
        raise InputError(
            f"{files[0]}: {int(rec.active.sum())} of the {what} ticks carry an active fault; "
            "commission on healthy running only"
        )
    return rec


def settling(x: np.ndarray, tick_hz: float, final: np.ndarray, delta: np.ndarray) -> list[dict]:
    """For growing prefixes of the healthy data: how far the baseline fitted on that prefix moves
    the residuals from where the final fit moves them, relative to the final shift's size."""
    b = baseline.basis(x.astype(np.float64), delta.shape[0])
    size = float(np.sqrt(np.mean(np.square(np.einsum("tjb,jcb->tjc", b, delta))))) or 1.0
    rows = []
    for minutes in MINUTES:
        n = int(minutes * 60 * tick_hz)
        if n > len(x):
            break
        gap = np.einsum("tjb,jcb->tjc", b, baseline.fit(x[:n]) - final)
        rows.append({"minutes": minutes, "relative_error": float(np.sqrt(np.mean(gap**2))) / size})
    return rows


def reads_residuals(graph: GraphSpec) -> bool:
    """Whether the model reads a residual channel on a joint: only then does the residual
    baseline, and how many minutes it took to settle, mean anything for it."""
    if graph.channel_mask is None:
        return True
    columns = [schema.feature_index(name) for name in baseline.RESIDUALS]
    return bool(graph.channel_mask[: graph.num_joints, columns].any())


def contact_record(rec: Recording, arm: str, sensing: str, margin: float | None) -> dict:
    """The contact watch's thresholds for this arm from its healthy running, or why there are
    none (no margin asked, a profile without the torque residual, no pose held long enough)."""
    needed = ("vel", "effort", "effort_residual")
    if margin is None:
        return {"skipped": "contact_margin=null"}
    if not set(needed) <= set(load_profile(sensing).joint_channels):
        return {"skipped": f"the sensing profile '{sensing}' lacks one of {', '.join(needed)}"}
    raw = to_raw(rec.x, arm)
    runs = [raw[rec.run == r] for r in range(len(rec.run_ids))]
    thresholds, how = commission_thresholds([r for r in runs if len(r)], arm, margin)
    if thresholds is None:
        return {"skipped": how}
    return {
        "threshold_nm": [round(float(v), 4) for v in thresholds],
        "rule": how,
        "quiet_nm": [round(float(v), 4) for v in thresholds / margin],  # placing's noise
    }


def arm_placement(graph: GraphSpec, placement: dict | None) -> np.ndarray:
    """Where this arm's harness sensors sit: ``placement`` (``coupling_seed`` and
    ``coupling_sensors``, ``coupling_file`` or ``coupling``, as ``graph=harness`` takes them),
    or the checkpoint's own. The simulation mixes the arm's data by it; the model is not told."""
    given = {k: v for k, v in (placement or {}).items() if v is not None}
    if not given:
        return graph.coupling
    m = graph.coupling.shape[1]
    c = harness_graph(**{"coupling_sensors": m, **given}).coupling
    if c.shape != graph.coupling.shape:
        raise InputError(
            f"placement: the model reads {m} sensors, the placement places {c.shape[1]}"
        )
    return c


def commission(
    ckpt_path: Path | str,
    healthy: list[str] | str,
    out_dir: Path | str,
    reference: list[str] | str | None = None,
    export: bool = True,
    tick_hz: float = 20.0,
    placement: dict | None = None,
    placement_fit: str = "motion",
    placement_prune: float | None = None,
    operating_point: str = "per_class",
    arm: str | None = None,
    healthy_rate: float | None = None,
    contact_margin: float | None = 2.0,
    normalisation: str = "none",
) -> dict[str, Any]:
    """Write ``out_dir/best.ckpt`` (and ``model.onnx`` for a network) commissioned on
    ``healthy``; the commissioning record (also in the checkpoint). A harness model with a
    coupling head also has its ``C`` refitted to the arm's ``placement``
    (:mod:`robohealth_mj.deploy.recouple`). ``arm``: the arm ``healthy`` comes from where it
    names none (a controller log, a bag). ``contact_margin``: the contact watch's thresholds over
    the healthy running's largest quiet deviations (None: no watch). ``normalisation``: how the
    z-scoring is refitted to the arm's healthy running (:mod:`robohealth_mj.deploy.renormalise`)."""
    check_recipe(operating_point, healthy_rate)  # before minutes of work, not after
    if normalisation not in MATCHES:
        raise InputError(f"normalisation: one of {', '.join(MATCHES)}, got {normalisation!r}")
    if contact_margin is not None and not contact_margin > 0:
        raise InputError(f"contact_margin: must be positive (or null), got {contact_margin}")
    ckpt = load_checkpoint(ckpt_path)
    healthy_files = expand_paths(healthy)
    arm_name = single_arm(healthy_files, arm, "healthy")
    arm = _healthy(ckpt, [str(f) for f in healthy_files], "healthy", arm_name)
    reference = reference or ckpt["config"].get("data", {}).get("train")
    if not reference:
        raise InputError(f"{ckpt_path}: no training data named in it: pass reference=DATA")
    # a model read on another arm (learn/other_arm.py): the reference is its source's to read
    source = (ckpt.get("read_as") or {}).get("checkpoint")
    ref_ckpt = load_checkpoint(source) if source else ckpt
    ref = _healthy(ref_ckpt, reference, "reference")
    ref_x = ref.x[~ref.active]
    w_ref, w_arm = baseline.fit(ref_x), baseline.fit(arm.x)
    if source:  # each joint against its UR counterpart's baseline
        w_ref = w_ref[[schema.JOINT_NAMES.index(c) for c in ckpt["read_as"]["counterparts"]]]
    delta = (w_arm - w_ref).astype(np.float32)
    trained = graph_from_checkpoint(ckpt)
    reads = reads_residuals(trained)
    rows = settling(arm.x, tick_hz, w_arm, delta) if reads else []
    settled = next(
        (r["minutes"] for k, r in enumerate(rows)
         if all(later["relative_error"] <= SETTLED for later in rows[k:])),
        None,
    )  # fmt: skip
    record = {
        "arm": arm_name,
        "healthy": [str(p) for p in healthy_files],
        "healthy_fingerprint": arm.fingerprint(),
        "healthy_minutes": round(len(arm) / tick_hz / 60.0, 2),
        "reference_fingerprint": ref.fingerprint(),
        "settling": rows,
        "settled_minutes": settled,
        "from_checkpoint": str(ckpt_path),
    }
    if not reads:
        record["settling_skipped"] = (
            f"the sensing profile '{trained.sensing}' reads no residual channel "
            f"({', '.join(baseline.RESIDUALS)})"
        )
    record["contact"] = contact_record(arm, arm_name, trained.sensing, contact_margin)
    graph = replace(trained.named_for(arm.graph), baseline_shift=delta)
    out_dir = Path(out_dir)
    model = model_from_checkpoint(ckpt)
    mean, std = ckpt["norm_mean"].numpy(), ckpt["norm_std"].numpy()
    ref_graph = graph_from_checkpoint(ref_ckpt)
    if normalisation != "none":
        reference_moments = healthy_moments(ref_graph.transform(ref_x))
        arm_moments = healthy_moments(graph.transform(arm.x))
        mean, std = match_healthy(mean, std, reference_moments, arm_moments, normalisation)
        record["normalisation"] = normalisation
    if graph.coupling is not None and getattr(model, "anomaly", None) is not None:
        graph = replace(graph, coupling=arm_placement(graph, placement))
        drawn = int((ckpt["config"].get("trainer") or {}).get("placements") or 0)
        mean, std, record["placement"] = recouple(
            model,
            graph,
            arm,
            ref,
            mean,
            std,
            int(ckpt["window"]),
            placement_fit,
            drawn > 0,
            prune=placement_prune,
        )
        # the placement found, as graph.coupling_file reads it: a model can be trained on it
        record["placement"]["file"] = str(out_dir / PLACEMENT)
        atomic_write_json(out_dir / PLACEMENT, record["placement"]["coupling"])
    elif placement:
        raise InputError(
            f"{ckpt_path}: placement= is for harness models with a coupling head; "
            "this model has no placement to calibrate"
        )
    offset, record["operating_point"] = match_operating_point(
        model,
        int(ckpt["window"]),
        Reading(ref, ref_graph, ref_ckpt["norm_mean"].numpy(),
                ref_ckpt["norm_std"].numpy()),
        list((ckpt.get("split_runs") or {}).get("val", [])),
        Reading(arm, graph, mean, std),
        operating_point,
        healthy_rate,
        model_from_checkpoint(ref_ckpt) if source else None,
    )  # fmt: skip
    save_checkpoint(
        out_dir / CHECKPOINT,
        model,
        model_cfg=ckpt["model_cfg"],
        variant=ckpt["variant"],
        graph=graph,
        window=int(ckpt["window"]),
        mean=mean,
        std=std,
        config=ckpt["config"],
        code_version=ckpt["code_version"],
        data_fingerprint=ckpt["data_fingerprint"],
        best_epoch=int(ckpt["best_epoch"]),
        extra={
            "gamma": ckpt.get("gamma"),
            "split_runs": ckpt.get("split_runs"),
            "arms": ckpt.get("arms"),
            "transfer": ckpt.get("transfer"),
            "commissioning": record,
            "class_offset": offset.tolist(),
            **({"read_as": ckpt["read_as"]} if source else {}),
        },
    )
    record["checkpoint"] = str(out_dir / CHECKPOINT)
    network = not callable(getattr(model, "fit", None))
    if export and network:
        result = export_checkpoint(
            out_dir / CHECKPOINT, out_dir / "model.onnx", data=healthy, arm=arm_name
        )
        record["onnx"] = result["path"]
        record["onnx_fingerprint"] = file_fingerprint(result["path"])
    return record
