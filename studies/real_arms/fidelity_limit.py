"""Fidelity against the controller's target moment: how the logged acceleration is estimated,
and what no estimate from the logged motion explains.

    python studies/real_arms/fidelity_limit.py > studies/real_arms/results/fidelity_limit.md

The twin's torque along a log is inverse dynamics of the log's motion, so its acceleration has to
be estimated from the logged velocity. Two choices enter: how the rows' uneven timing is treated
(these logs step 10 or 12 ms) and the low-pass before differentiation.

Part 1, the estimator (an ablation): per estimator and cutoff, the selection score (the mean
NRMSE on a fit log left out, which ``identify cutoff_hz=auto`` minimises) and the NRMSE on the
validation logs, which select nothing. "Rows as evenly spaced" is the estimator before
2026-11-27, rebuilt here for the comparison.

Part 2, the limit: on each validation log and joint, at the twin's cutoff, the twin's NRMSE
beside figures of the log alone: the target moment's content above the cutoff (its NRMSE
against its own zero-phase low-pass: what a low-passed acceleration cannot carry), the twin
against that low-pass (the target on what the estimated motion can carry), and what is
left after the best linear filter of the measured motion (every joint's velocity, -0.1 s to +0.1 s,
least squares) takes out all it can of the twin's residual: fitted on the rows it is scored on
(optimistic: what it leaves, no estimate built from the logged motion removes) and fitted on the
log's other half (what such a filter would really deliver). Both run on a uniform 100 Hz grid, so
the twin's figure on that grid stands beside them.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from unittest import mock

import numpy as np
import yaml
from scipy.signal import butter, filtfilt

from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.twin import identify as twin_identify
from robohealth_mj.twin.joint_log import JointLog, read_joint_log

ROOT = Path("outputs/real_arms")
LOGS = ROOT / "logs"
ID = LOGS / "identification_data"
# as studies/real_arms/campaign.py's LOGS_ROLES
FIT = [ID / f for f in ("ur-20_02_12-50sec_12harm.csv", "ur-20_02_12-40sec_12harm.csv",
                        "ur-20_02_10-30sec_12harm.csv")]  # fmt: skip
VALIDATE = [ID / "ur-20_02_19_14harm50sec.csv",
            LOGS / "validation_data" / "ur-20_01_17-ptp_10_points.csv",
            ID / "ur-19_12_23_free.csv"]  # fmt: skip
TWIN = ROOT / "identified" / "twin.yaml"  # as studies/real_arms/run.sh identifies it
ARM = "ur10e"
SHORT = ("pan", "lift", "elbow", "w1", "w2", "w3")
FIR_S = 0.1  # the oracle filter's reach either side of a row
FIR_HZ = 100.0  # the grid the oracle filter runs on


def rows_as_evenly_spaced(log: JointLog, cutoff_hz: float) -> twin_identify.Motion:
    """The estimator before 2026-11-27: the rows filtered as if evenly spaced at the median
    step, then differentiated against their own time stamps."""
    rate = log.rate_hz
    b, a = butter(2, min(cutoff_hz, 0.4 * rate) / (0.5 * rate))
    qd = filtfilt(b, a, log.qd, axis=0)
    qdd = np.gradient(qd, log.t, axis=0)
    return twin_identify.Motion(log.q, qd, qdd, np.tanh(qd / twin_identify.SIGN_VELOCITY))


@contextmanager
def estimator(name: str) -> Iterator[None]:
    """Within it, identification estimates the acceleration the way ``name`` says."""
    if name == "rows as evenly spaced":
        with mock.patch.object(twin_identify, "motion", rows_as_evenly_spaced):
            yield
    else:
        yield


def percent(v: float) -> str:
    return f"{100 * v:.2f}"


def estimator_table(fit: list[JointLog], validate: list[JointLog]) -> list[str]:
    head = ["estimator", "cutoff Hz", "selection: fit log left out", "pan armature kg m2"]
    head += [f"{log.name}: max (pan, w3)" for log in validate]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for name in ("rows as evenly spaced", "uniform grid"):
        with estimator(name):
            chosen, scores = twin_identify.choose_cutoff(ARM, fit)
            for cutoff, score in scores.items():
                drives = twin_identify.identify(ARM, fit, cutoff).drives
                cells = []
                for log in validate:
                    e = twin_identify.fidelity(ARM, log, drives, cutoff)["vs_target_moment"]
                    cells.append(f"{percent(e.max())} ({percent(e[0])}, {percent(e[5])})")
                mark = " (chosen)" if cutoff == chosen else ""
                lines.append(f"| {name} | {cutoff:g}{mark} | {percent(score)} | "
                             f"{drives.armature[0]:.2f} | " + " | ".join(cells) + " |")  # fmt: skip
    return lines


def on_grid(log: JointLog, x: np.ndarray, hz: float) -> tuple[np.ndarray, np.ndarray]:
    grid = np.arange(log.t[0], log.t[-1], 1.0 / hz)
    return grid, np.stack([np.interp(grid, log.t, x[:, j]) for j in range(x.shape[1])], axis=1)


def up_to_cutoff(log: JointLog, cutoff_hz: float) -> np.ndarray:
    """``[T, 6]`` the target moment's content up to the cutoff: its zero-phase low-pass on the
    uniform grid the twin's acceleration is estimated on, read back at the rows."""
    grid, moment = twin_identify.on_uniform_grid(log.t, log.model_torque)
    return twin_identify.at_rows(log.t, grid, twin_identify.low_pass(moment, cutoff_hz))


def nrmse_of_range(x: np.ndarray, y: np.ndarray, log: JointLog) -> np.ndarray:
    """``[6]`` RMS of ``x - y`` over the target moment's range on the log (as every row here)."""
    return np.sqrt(np.mean((x - y) ** 2, axis=0)) / np.ptp(log.model_torque, axis=0)


def best_filter(log: JointLog, residual: np.ndarray) -> dict[str, np.ndarray]:
    """On the FIR_HZ grid, ``[6]`` each: the residual's RMS over the moment's range as it is,
    after the best FIR filter of the six measured velocities (taps -FIR_S..+FIR_S) fitted on the
    same rows is subtracted, and after one fitted on the log's other half."""
    _, qd = on_grid(log, log.qd, FIR_HZ)
    _, res = on_grid(log, residual, FIR_HZ)
    k = round(FIR_S * FIR_HZ)
    taps = [np.roll(qd[:, j], s) for j in range(qd.shape[1]) for s in range(-k, k + 1)]
    x = np.column_stack([*taps, np.ones(len(qd))])[k:-k]
    y = res[k:-k]
    half = len(y) // 2
    other = []
    for fit, test in ((slice(0, half), slice(half, None)), (slice(half, None), slice(0, half))):
        other.append(y[test] - x[test] @ np.linalg.lstsq(x[fit], y[fit], rcond=None)[0])
    span = np.ptp(log.model_torque, axis=0)

    def rms(v: np.ndarray) -> np.ndarray:
        return np.sqrt(np.mean(v**2, axis=0)) / span

    return {
        "twin": rms(y),
        "in-sample": rms(y - x @ np.linalg.lstsq(x, y, rcond=None)[0]),
        "other half": rms(np.concatenate(other)),
    }


def limit_table(validate: list[JointLog], twin: dict) -> list[str]:
    cutoff = float(twin["fit"]["cutoff_hz"])
    overrides = twin["drive_overrides"]
    drives = twin_identify.Drives(
        *(np.array([overrides[j][p] for j in JOINT_NAMES]) for p in twin_identify.PARAMETERS),
        np.array(twin["torque_constant_nm_per_a"]),
    )
    lines = ["| log | figure | " + " | ".join(SHORT) + " |", "|" + "---|" * (len(SHORT) + 2)]
    for log in validate:
        m = twin_identify.motion(log, cutoff)
        simulated = drives.model_torque(twin_identify.rigid_torques(ARM, m), m)
        fir = best_filter(log, log.model_torque - simulated)
        smooth = up_to_cutoff(log, cutoff)
        grid = f"{FIR_HZ:g} Hz grid:"
        rows = {
            "twin vs target moment": twin_identify.nrmse(simulated, log.model_torque),
            f"target moment above {cutoff:g} Hz": nrmse_of_range(smooth, log.model_torque, log),
            f"twin vs the target moment up to {cutoff:g} Hz": nrmse_of_range(
                simulated, smooth, log
            ),
            f"{grid} twin": fir["twin"],
            f"{grid} left by the best filter of the motion fitted on these rows": fir["in-sample"],
            f"{grid} left by that filter fitted on the log's other half": fir["other half"],
        }
        for label, values in rows.items():
            cells = " | ".join(percent(v) for v in values)
            lines.append(f"| {log.name} ({log.t[-1]:.1f} s) | {label} | {cells} |")
    return lines


def main() -> None:
    fit = [read_joint_log(p) for p in FIT]
    validate = [read_joint_log(p) for p in VALIDATE]
    twin = yaml.safe_load(TWIN.read_text())
    print("# Fidelity against the target moment: the acceleration's estimate, and the limit\n")
    print("Command: `python studies/real_arms/fidelity_limit.py` (after `identify`, which")
    print(f"writes `{TWIN}`). NRMSE in % of the joint's range on that log.\n")
    print("## The estimator (selection on the fit logs only)\n")
    print("\n".join(estimator_table(fit, validate)))
    print(f"\n## What the logged motion cannot explain (twin's cutoff {twin['fit']['cutoff_hz']:g}"
          " Hz)\n")  # fmt: skip
    print("\n".join(limit_table(validate, twin)))


if __name__ == "__main__":
    main()
