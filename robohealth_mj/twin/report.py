"""Identification as the ``identify`` tool runs it: fit, write the twin file, tabulate fidelity."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.version import code_version
from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.twin_file import write_twin
from robohealth_mj.twin.identify import fidelity, friction_floor, identify, nominal_drives
from robohealth_mj.twin.joint_log import read_joint_log

SHORT = ("pan", "lift", "elbow", "w1", "w2", "w3")


def run_identification(
    arm: str,
    fit: list[str],
    validate: list[str],
    column_map: str | None,
    out: Path,
    cutoff_hz: float | None = None,
) -> dict:
    """Fit on ``fit``, write ``out/twin.yaml`` and tabulate fidelity on ``validate``; the
    velocity low-passed at ``cutoff_hz`` (None: chosen on the fit logs)."""
    fit_logs = [read_joint_log(p, column_map) for p in fit]
    val_logs = [read_joint_log(p, column_map) for p in validate]
    found = identify(arm, fit_logs, cutoff_hz)
    drives, cutoff = found.drives, found.cutoff_hz
    in_sample = [fidelity(arm, log, drives, cutoff) for log in fit_logs]
    twin = {
        "arm": arm,
        "drive_overrides": drives.overrides(),
        "torque_constant_nm_per_a": [round(float(v), 4) for v in drives.torque_constant],
        # the measured torque's noise per 20 Hz tick (holds in the fit logs): what the simulated
        # effort reads with instead of the torque sensor's default
        "effort_noise_nm": None if found.effort_noise is None else _list(found.effort_noise),
        "fit": {
            "logs": [Path(p).name for p in fit],
            "rows": found.rows,
            "seconds": round(found.seconds, 1),
            "used_model_torque": found.used_model_torque,
            "notes": found.notes,
            # the velocity's low-pass before differentiation, and how it was chosen: the mean
            # NRMSE on a fit log left out, per cutoff tried (absent: the cutoff was given)
            "cutoff_hz": cutoff,
            **_cutoff_scores(found.cutoff_scores),
            # the fit's own residuals (NRMSE of the joint's range, on the fit logs)
            "residual_vs_current": _rows(in_sample, "vs_current"),
            "residual_vs_target_moment": _rows(in_sample, "vs_target_moment"),
        },
        "method": "robohealth_mj/twin/identify.py",
        "code_version": code_version(),
    }
    out.mkdir(parents=True, exist_ok=True)
    write_twin(out / "twin.yaml", twin)
    result = {"twin": twin, "twin_file": str(out / "twin.yaml"), "fidelity": [],
              "fidelity_md": ""}  # fmt: skip
    if not val_logs:
        return result
    floor = friction_floor(fit_logs, cutoff) if found.used_model_torque else None
    nominal = nominal_drives(arm)
    nominal.torque_constant = drives.torque_constant  # one k_t: the fidelity is the model's
    rows = []
    for log in val_logs:
        before = fidelity(arm, log, nominal, cutoff)
        after = fidelity(arm, log, drives, cutoff, floor)
        rows.append({"log": log.name, "seconds": after["seconds"],
                     **{f"before_{k}": _list(v) for k, v in before.items() if k.startswith("vs")},
                     **{f"after_{k}": _list(v) for k, v in after.items()
                        if k.startswith(("vs", "floor"))}})  # fmt: skip
    result["fidelity"] = rows
    result["fidelity_md"] = fidelity_table(rows)
    return result


def _cutoff_scores(scores: dict[float, float] | None) -> dict:
    if scores is None:
        return {}
    return {"held_out_nrmse_by_cutoff_hz": {float(c): round(v, 6) for c, v in scores.items()}}


def _list(v: np.ndarray) -> list[float]:
    return [round(float(x), 5) for x in v]


def _rows(items: list[dict], key: str) -> dict[str, list[float]]:
    return {item["log"]: _list(item[key]) for item in items if key in item}


def fidelity_table(rows: list[dict]) -> str:
    """Markdown: per validation log and comparison, NRMSE (%) per joint."""
    head = "| log | comparison | " + " | ".join(SHORT) + " |"
    lines = [head, "|" + "---|" * (len(SHORT) + 2)]
    labels = [
        ("before_vs_target_moment", "sim before id. vs target moment"),
        ("after_vs_target_moment", "sim after id. vs target moment"),
        ("before_vs_current", "sim before id. vs current x k_t"),
        ("after_vs_current", "sim after id. vs current x k_t"),
        ("after_floor_vs_current", "floor: target moment + friction vs current x k_t"),
    ]
    for row in rows:
        for key, label in labels:
            if key in row:
                cells = " | ".join(f"{100 * v:.2f}" for v in row[key])
                lines.append(f"| {row['log']} ({row['seconds']:g} s) | {label} | {cells} |")
    lines.append("")
    lines.append("NRMSE in % of the joint's range on that log; joints " + ", ".join(
        f"{s} = {j}" for s, j in zip(SHORT, JOINT_NAMES, strict=True)))  # fmt: skip
    return "\n".join(lines) + "\n"


def cutoff_choice(value: Any) -> float | None:
    """``cutoff_hz``: a frequency in Hz, or ``auto`` (None: chosen on the fit logs)."""
    if value == "auto":
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise InputError(f"cutoff_hz: a frequency in Hz > 0 or auto, got {value!r}")
    return float(value)


def identification_summary(result: dict, arm: str, logs: int) -> str:
    """What ``python -m robohealth_mj.identify`` prints: the fit, the velocity filter and how it
    was chosen, each joint's drive, the fidelity table and the command that records on it."""
    twin, fitted = result["twin"], result["twin"]["fit"]
    tried = fitted.get("held_out_nrmse_by_cutoff_hz")
    how = ("given" if tried is None else "chosen on the fit logs, mean NRMSE on one left out: "
           + ", ".join(f"{c:g} Hz {100 * v:.2f} %" for c, v in tried.items()))  # fmt: skip
    lines = [f"fitted on {fitted['seconds']:g} s of {logs} log(s) -> {result['twin_file']}",
             f"  velocity low-pass {fitted['cutoff_hz']:g} Hz ({how})"]  # fmt: skip
    k_t = twin["torque_constant_nm_per_a"]
    for j, joint in enumerate(JOINT_NAMES):
        d = twin["drive_overrides"][joint]
        lines.append(f"  {joint:14s} armature {d['armature']:7.3f}  damping {d['damping']:7.3f}  "
                     f"frictionloss {d['frictionloss']:7.3f}  k_t {k_t[j]:6.3f}")  # fmt: skip
    if result["fidelity_md"]:
        lines.append(result["fidelity_md"])
    lines.append(f"record on it: python -m robohealth_mj.record arm={arm} "
                 f"sim.twin={result['twin_file']}")  # fmt: skip
    return "\n".join(lines)
