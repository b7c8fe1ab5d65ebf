"""Identifying a real arm's drives from its controller log.

The simulated arm of the log's type is driven along the logged joint trajectory: MuJoCo's inverse
dynamics of its compiled model (links from UR's published parameters) give the rigid-body torque
each joint needs at each row. What our drive model adds per joint is linear in its parameters,

    tau = rigid(q, qd, qdd) + armature * qdd + damping * qd + frictionloss * sign(qd)

and the log measures it twice: the controller's own model torque (``target_moment``, which has no
friction) and the motor current, ``i = tau / k_t``. So, per joint, by non-negative least squares:
the rotor inertia from the model torque (where the log has one), then ``i`` on ``[rigid +
armature * qdd, qd, sign(qd)]``, whose coefficients are ``1/k_t``, ``damping/k_t`` and
``frictionloss/k_t`` (with no model torque in the log the rotor inertia joins that fit).

The acceleration is the logged velocity's derivative after a zero-phase low-pass, whose cutoff
trades noise against the fast part of the motion. By default it is chosen per arm by
leave-one-log-out on the fit logs (:func:`choose_cutoff`), never on the logs it is validated on.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np
from scipy.optimize import nnls
from scipy.signal import butter, sosfiltfilt

from robohealth_mj.common.errors import InputError
from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.dynamics import nominal_model
from robohealth_mj.sim.twin_file import PARAMETERS
from robohealth_mj.twin.joint_log import JointLog

SIGN_VELOCITY = 0.02  # rad/s: sign(qd) as tanh(qd / this), so friction is smooth through rest
CUTOFF_GRID_HZ = (3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0)  # the low-passes choose_cutoff tries
UNIFORM_HZ = 500.0  # the grid the velocity is filtered on: the e-Series controller's cycle
STILL_RAD_S = 1e-3  # every joint slower than this: the arm holds still
MOVING_RAD_S = 1e-3  # a joint whose velocity spans less in the fit logs is not identified
STILL_S = 1.0  # the shortest hold the measurement noise is read from
TICK_HZ = 20.0  # the recordings' tick rate: the noise is what one tick reads


@dataclass
class Motion:
    """A log's trajectory as identification uses it: ``[T, 6]`` each."""

    q: np.ndarray
    qd: np.ndarray  # low-passed, zero phase
    qdd: np.ndarray  # of the low-passed velocity
    sign: np.ndarray  # tanh(qd / SIGN_VELOCITY)


def motion(log: JointLog, cutoff_hz: float) -> Motion:
    """The log's trajectory with its velocity low-passed at ``cutoff_hz`` (at most 0.4 x the
    log's rate) and differentiated. A logger's rows come unevenly (on the public UR10e logs a
    third of the steps are 12 ms, not 10), and a filter that takes them as evenly spaced bends the
    acceleration; so the velocity is interpolated onto a uniform grid, filtered and
    differentiated there, and read back at the rows."""
    grid, qd = on_uniform_grid(log.t, log.qd)
    qd = low_pass(qd, min(float(cutoff_hz), 0.4 * log.rate_hz))
    qd_rows = at_rows(log.t, grid, qd)
    qdd = at_rows(log.t, grid, np.gradient(qd, grid, axis=0))
    return Motion(log.q, qd_rows, qdd, np.tanh(qd_rows / SIGN_VELOCITY))


def on_uniform_grid(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x [T, C]`` logged at times ``t`` interpolated onto a grid at UNIFORM_HZ: (grid, values)."""
    grid = np.arange(t[0], t[-1] + 0.5 / UNIFORM_HZ, 1.0 / UNIFORM_HZ)
    return grid, np.stack([np.interp(grid, t, x[:, c]) for c in range(x.shape[1])], axis=1)


def low_pass(x: np.ndarray, cutoff_hz: float) -> np.ndarray:
    """``x`` on the uniform grid, low-passed without phase lag (left as it is when too short)."""
    if len(x) <= 15:
        return x
    return sosfiltfilt(butter(2, cutoff_hz, fs=UNIFORM_HZ, output="sos"), x, axis=0)


def at_rows(t: np.ndarray, grid: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``x`` on the uniform grid read back at the log's times ``t``."""
    return np.stack([np.interp(t, grid, x[:, c]) for c in range(x.shape[1])], axis=1)


def rigid_torques(arm: str, m: Motion, payload_kg: float = 0.0) -> np.ndarray:
    """``[T, 6]`` the links' torque along the motion on the simulated ``arm`` (UR's published
    inertials; no drive: its armature and damping are taken out, friction is off)."""
    nominal, idx = nominal_model(arm)
    model = copy.copy(nominal)  # the cached model is never edited
    model.opt.disableflags |= (
        mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS
        | mujoco.mjtDisableBit.mjDSBL_CONTACT
        | mujoco.mjtDisableBit.mjDSBL_LIMIT
    )
    model.body_mass[idx.payload_body] = payload_kg
    data = mujoco.MjData(model)
    out = np.empty_like(m.q)
    for k in range(len(m.q)):
        data.qpos[idx.motor_qpos] = m.q[k]
        data.qpos[idx.deflection_qpos] = 0.0
        data.qvel[:] = 0.0
        data.qvel[idx.motor_dof] = m.qd[k]
        data.qacc[:] = 0.0
        data.qacc[idx.motor_dof] = m.qdd[k]
        mujoco.mj_inverse(model, data)
        out[k] = data.qfrc_inverse[idx.motor_dof]
    dof = idx.motor_dof
    return out - model.dof_armature[dof] * m.qdd - model.dof_damping[dof] * m.qd


@dataclass
class Drives:
    """Per joint (schema order) drive parameters and torque constant."""

    armature: np.ndarray
    damping: np.ndarray
    frictionloss: np.ndarray
    torque_constant: np.ndarray | None = None  # N*m per A; None: not identified (nominal)

    def model_torque(self, rigid: np.ndarray, m: Motion) -> np.ndarray:
        """What a controller's model computes: rigid body and rotor inertia, no friction."""
        return rigid + self.armature * m.qdd

    def torque(self, rigid: np.ndarray, m: Motion) -> np.ndarray:
        """The drive's whole torque: the model torque and friction, viscous and Coulomb."""
        return self.model_torque(rigid, m) + self.damping * m.qd + self.frictionloss * m.sign

    def overrides(self) -> dict[str, dict[str, float]]:
        return {
            joint: {p: round(float(getattr(self, p)[j]), 6) for p in PARAMETERS}
            for j, joint in enumerate(JOINT_NAMES)
        }


def nominal_drives(arm: str) -> Drives:
    """The simulator's drive parameters for ``arm`` before identification."""
    model, idx = nominal_model(arm)
    dof = idx.motor_dof
    return Drives(model.dof_armature[dof].copy(), model.dof_damping[dof].copy(),
                  model.dof_frictionloss[dof].copy())  # fmt: skip


@dataclass
class Identified:
    drives: Drives
    rows: int
    seconds: float
    used_model_torque: bool
    cutoff_hz: float  # the velocity's low-pass the fit used
    notes: list[str] = field(default_factory=list)
    effort_noise: np.ndarray | None = None  # N*m per tick, per joint; None: no hold to read it
    cutoff_scores: dict[float, float] | None = None  # choose_cutoff's table; None: cutoff given


def effort_noise(logs: Sequence[JointLog], k_t: np.ndarray) -> np.ndarray | None:
    """Per joint, the measured torque's noise as one 20 Hz tick reads it (N*m): while the arm
    holds still for a second or more, the spread of tick-to-tick differences of current x k_t
    over sqrt(2), which a hold's own offset (where static friction left the joint) does not
    enter. Our simulator's default is a torque sensor's; a real drive's current is noisier."""
    steps = []
    for log in logs:
        still = np.abs(log.qd).max(axis=1) < STILL_RAD_S
        stride = max(1, round(log.rate_hz / TICK_HZ))
        edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(int), [0]])))
        for start, end in zip(edges[::2], edges[1::2], strict=True):
            if log.t[end - 1] - log.t[start] >= STILL_S:
                steps.append(np.diff(log.current[start:end:stride] * k_t, axis=0))
    if not steps or sum(len(s) for s in steps) < 20:
        return None
    return np.concatenate(steps).std(axis=0) / np.sqrt(2.0)


@dataclass
class _Prepared:
    """One log as the fit reads it: the log, its motion and the links' torque along it."""

    log: JointLog
    motion: Motion
    rigid: np.ndarray


def _prepare(arm: str, logs: Sequence[JointLog], cutoff_hz: float) -> list[_Prepared]:
    out = []
    for log in logs:
        m = motion(log, cutoff_hz)
        out.append(_Prepared(log, m, rigid_torques(arm, m)))
    return out


def _fit(prepared: Sequence[_Prepared]) -> Drives:
    """Per joint, by non-negative least squares on the pooled rows (see the module's
    docstring): rotor inertia, viscous and Coulomb friction and torque constant."""
    rigid = np.concatenate([p.rigid for p in prepared])
    qdd = np.concatenate([p.motion.qdd for p in prepared])
    qd = np.concatenate([p.motion.qd for p in prepared])
    sign = np.concatenate([p.motion.sign for p in prepared])
    current = np.concatenate([p.log.current for p in prepared])
    with_model = all(p.log.model_torque is not None for p in prepared)
    if with_model:
        model_torque = np.concatenate([p.log.model_torque for p in prepared])
    armature, damping, friction, k_t = (np.zeros(len(JOINT_NAMES)) for _ in range(4))
    for j, joint in enumerate(JOINT_NAMES):
        if np.ptp(qd[:, j]) < MOVING_RAD_S:
            raise InputError(f"identify: joint {joint} does not move in the fit logs")
        if with_model:
            armature[j] = nnls(qdd[:, [j]], model_torque[:, j] - rigid[:, j])[0][0]
            columns = [rigid[:, j] + armature[j] * qdd[:, j], qd[:, j], sign[:, j]]
        else:
            columns = [rigid[:, j], qdd[:, j], qd[:, j], sign[:, j]]
        coef = nnls(np.stack(columns, axis=1), current[:, j])[0]
        if coef[0] <= 0:
            raise InputError(f"identify: joint {joint}: current does not follow the torque; is "
                             "the effort column a current of this joint?")  # fmt: skip
        k_t[j] = 1.0 / coef[0]
        if not with_model:
            armature[j] = coef[1] * k_t[j]
            coef = np.delete(coef, 1)
        damping[j], friction[j] = coef[1] * k_t[j], coef[2] * k_t[j]
    return Drives(armature, damping, friction, k_t)


def _held_out_error(p: _Prepared, drives: Drives) -> float:
    """Mean NRMSE over the joints on a log the fit did not see: the model torque against the
    target moment where the log has one, else the whole torque against current x k_t."""
    if p.log.model_torque is not None:
        return float(nrmse(drives.model_torque(p.rigid, p.motion), p.log.model_torque).mean())
    measured = p.log.current * drives.torque_constant
    return float(nrmse(drives.torque(p.rigid, p.motion), measured).mean())


def _halves(log: JointLog) -> list[JointLog]:
    mid = len(log.t) // 2
    return [JointLog(f"{log.source}[{a}:{b}]", log.t[a:b], log.q[a:b], log.qd[a:b],
                     log.current[a:b], None if log.model_torque is None else log.model_torque[a:b])
            for a, b in ((0, mid), (mid, len(log.t)))]  # fmt: skip


def choose_cutoff(arm: str, logs: Sequence[JointLog]) -> tuple[float, dict[float, float]]:
    """The velocity low-pass (of CUTOFF_GRID_HZ) whose fit best predicts a fit log it left out:
    each log in turn is held out (a single log: its two halves), the rest fitted, and the
    held-out error averaged (a fold whose other logs leave a joint still is not scored).
    Returns the cutoff and the mean error per cutoff tried."""
    cutoff, scores, _ = _choose_cutoff(arm, logs)
    return cutoff, scores


def _choose_cutoff(
    arm: str, logs: Sequence[JointLog]
) -> tuple[float, dict[float, float], list[_Prepared] | None]:
    """:func:`choose_cutoff`, and the logs prepared at the chosen cutoff where the folds are the
    logs themselves (two or more), for the fit to reuse."""
    folds = list(logs) if len(logs) >= 2 else _halves(logs[0])
    highest = 0.4 * min(log.rate_hz for log in folds)
    scores: dict[float, float] = {}
    best, best_prepared = None, None
    for cutoff in (c for c in CUTOFF_GRID_HZ if c <= highest):
        prepared = _prepare(arm, folds, cutoff)
        errors = []
        for k, held_out in enumerate(prepared):
            if _all_joints_move(prepared[:k] + prepared[k + 1 :]):
                errors.append(_held_out_error(held_out, _fit(prepared[:k] + prepared[k + 1 :])))
        if errors:
            scores[cutoff] = float(np.mean(errors))
            if best is None or scores[cutoff] < scores[best]:  # ties: the lower cutoff
                best, best_prepared = cutoff, prepared
    if best is None:
        raise InputError("identify: cutoff_hz=auto found nothing to score it on (every joint "
                         "must move in the fit logs without any one of them, logged at 7.5 Hz or "
                         "more); pass cutoff_hz=")  # fmt: skip
    return best, scores, best_prepared if len(logs) >= 2 else None


def _all_joints_move(prepared: Sequence[_Prepared]) -> bool:
    qd = np.concatenate([p.motion.qd for p in prepared])
    return bool((np.ptp(qd, axis=0) >= MOVING_RAD_S).all())


def identify(arm: str, logs: Sequence[JointLog], cutoff_hz: float | None = None) -> Identified:
    """Each joint's rotor inertia, viscous and Coulomb friction and torque constant, fitted on
    ``logs`` (healthy running, no payload) pooled; the velocity low-passed at ``cutoff_hz``
    (None: chosen by :func:`choose_cutoff`)."""
    if not logs:
        raise InputError("identify: no log to fit on")
    scores = prepared = None
    if cutoff_hz is None:
        cutoff_hz, scores, prepared = _choose_cutoff(arm, logs)
    drives = _fit(prepared or _prepare(arm, logs, cutoff_hz))
    with_model = all(log.model_torque is not None for log in logs)
    notes = [] if with_model else ["no model torque in the logs: rotor inertia fitted on current"]
    noise = effort_noise(logs, drives.torque_constant)
    if noise is None:
        notes.append("no hold of 1 s or more in the logs: the simulator's effort noise is kept")
    rows = sum(len(log.t) for log in logs)
    seconds = float(sum(log.t[-1] - log.t[0] for log in logs))
    return Identified(drives, rows, seconds, with_model, float(cutoff_hz), notes, noise, scores)


def nrmse(simulated: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """``[6]`` RMS error over the measured signal's range on that log (per joint)."""
    span = np.ptp(measured, axis=0)
    return np.sqrt(np.mean((simulated - measured) ** 2, axis=0)) / np.where(span > 0, span, 1.0)


def friction_floor(logs: Sequence[JointLog], cutoff_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """The controller's own model as a current predictor: per joint, ``i`` on ``[target moment,
    qd, sign(qd)]`` fitted on ``logs``; ``([6, 3] coefficients, [6] torque constants)``."""
    motions = [motion(log, cutoff_hz) for log in logs]
    tau = np.concatenate([log.model_torque for log in logs])
    qd = np.concatenate([m.qd for m in motions])
    sign = np.concatenate([m.sign for m in motions])
    current = np.concatenate([log.current for log in logs])
    coef = np.stack([nnls(np.stack([tau[:, j], qd[:, j], sign[:, j]], 1), current[:, j])[0]
                     for j in range(len(JOINT_NAMES))])  # fmt: skip
    return coef, 1.0 / np.where(coef[:, 0] > 0, coef[:, 0], np.nan)


def fidelity(
    arm: str,
    log: JointLog,
    drives: Drives,
    cutoff_hz: float,
    floor: tuple[np.ndarray, np.ndarray] | None = None,
) -> dict:
    """NRMSE per joint of the simulated torque against the log's: the model torque against the
    controller's target moment, the whole torque against current x k_t (``drives``' k_t), and
    the floor (target moment and fitted friction against the same) where ``floor`` is given."""
    m = motion(log, cutoff_hz)
    rigid = rigid_torques(arm, m)
    k_t = drives.torque_constant
    out = {"log": log.name, "seconds": round(float(log.t[-1]), 1)}
    if log.model_torque is not None:
        out["vs_target_moment"] = nrmse(drives.model_torque(rigid, m), log.model_torque)
    if k_t is not None:
        measured = log.current * k_t
        out["vs_current"] = nrmse(drives.torque(rigid, m), measured)
        if floor is not None and log.model_torque is not None:
            coef, k_floor = floor
            predicted = coef[:, 0] * log.model_torque + coef[:, 1] * m.qd + coef[:, 2] * m.sign
            out["floor_vs_current"] = nrmse(predicted * k_floor, log.current * k_floor)
    return out
