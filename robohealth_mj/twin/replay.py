"""The arm's own program as a curriculum: joint trajectories replayed from its controller logs.

A model trained on our sweeps and payloads meets, on a real arm, motions it never saw (harmonic
excitation, point-to-point moves, long holds) and no payload; its healthy class does not cover
them. ``curriculum=replay curriculum.files=[LOG,...]`` drives the simulated arm (the twin, with
``sim.twin=``) along the logged positions instead, so faults are injected into the arm's own
motions. Each log's position is low-pass filtered (zero phase) and joined to the next log by a
quintic move from rest to rest, then held for a seeded while; the passes (each a seeded order of
the logs at a seeded speed scale) loop, so the reference is a periodic C2 spline at any length.
It serves the same interface as :class:`robohealth_mj.sim.curriculum.Curriculum`.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.signal import butter, sosfiltfilt

from robohealth_mj.arms.description import DEFAULT_ARM, ArmDescription, load_arm
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.seeds import stream
from robohealth_mj.schema import N_JOINTS
from robohealth_mj.sim.curriculum import ScheduledSegment, Segment, smoothstep
from robohealth_mj.twin.joint_log import read_joint_log

GRID_HZ = 100.0  # the program is built on this grid before the spline joins it up
MOVE_SPEED = 0.5  # of each joint's speed limit: the peak speed of a move between two logs


def _filtered_positions(path: str, column_map: str | None, cutoff_hz: float) -> np.ndarray:
    """A log's joint positions ``[T, 6]`` on the program's grid, zero-phase low-passed."""
    log = read_joint_log(path, column_map)
    grid = np.arange(0.0, log.t[-1], 1.0 / GRID_HZ)
    q = np.stack([np.interp(grid, log.t, log.q[:, j]) for j in range(N_JOINTS)], axis=1)
    if len(grid) < 30:
        raise InputError(f"{path}: {log.t[-1]:.2f} s of motion; a replayed log needs 0.3 s or more")
    sos = butter(2, cutoff_hz, fs=GRID_HZ, output="sos")
    return sosfiltfilt(sos, q, axis=0)


def _move(start: np.ndarray, end: np.ndarray, limits: np.ndarray, shortest_s: float) -> np.ndarray:
    """A quintic move from rest to rest on the grid (excluding its start), at most MOVE_SPEED of
    each joint's limit (a quintic's peak speed is 1.875 x distance / duration)."""
    duration = max(shortest_s, float(np.max(1.875 * np.abs(end - start) / (MOVE_SPEED * limits))))
    steps = int(np.ceil(duration * GRID_HZ))
    return start + (end - start) * smoothstep(np.arange(1, steps + 1) / steps)[:, None]


class ReplayCurriculum:
    """Serves the reference trajectory of the logged program (see the module's docstring)."""

    payload_ramp_s = 0.0  # the payload is the program's, constant for the session

    def __init__(
        self,
        files: Sequence[str],
        speed_scales: Sequence[float] = (1.0,),
        payload_kg: float = 0.0,
        passes: int = 4,
        hold_s: float = 6.0,
        blend_s: float = 1.5,
        segment_s: float = 10.0,
        cutoff_hz: float = 5.0,
        column_map: str | None = None,
        seed: int = 0,
        rated_payload_kg: float | None = None,
        speed_limit_rad_s: Sequence[float] | None = None,
        arm: ArmDescription | None = None,
    ) -> None:
        """``files``: the arm's healthy logs (positions in rad); ``speed_scales``: each log's
        replay runs this much faster (drawn per log and pass); ``payload_kg``: the payload the
        program carries; ``hold_s``: after each log the arm holds still for up to this long;
        ``arm``: the simulated arm (a UR controller's log has six joints: one of six)."""
        if arm is not None and arm.n_joints != N_JOINTS:
            raise InputError(
                f"curriculum=replay plays a UR controller's six-joint logs; the arm "
                f"{arm.name} has {arm.n_joints} joints"
            )
        if not files:
            raise InputError("curriculum.files: name at least one log to replay")
        if not speed_scales or min(speed_scales) <= 0:
            raise InputError(f"curriculum.speed_scales: positive values, got {list(speed_scales)}")
        if int(passes) < 1 or hold_s < 0 or blend_s <= 0 or segment_s <= 0:
            raise InputError("curriculum: passes >= 1, hold_s >= 0, blend_s > 0, segment_s > 0")
        if not 0.0 < cutoff_hz < GRID_HZ / 2:
            raise InputError(f"curriculum.cutoff_hz: in (0, {GRID_HZ / 2:g}), got {cutoff_hz}")
        default = load_arm(DEFAULT_ARM)
        rated = default.payload_kg if rated_payload_kg is None else float(rated_payload_kg)
        if not 0.0 <= payload_kg <= rated:
            raise InputError(f"curriculum.payload_kg: in [0, {rated:g}] (rated), got {payload_kg}")
        limits = np.asarray(default.speed_limit if speed_limit_rad_s is None else speed_limit_rad_s)
        self.files = [str(Path(f)) for f in files]
        self.speed_scales = [float(s) for s in speed_scales]
        self.payload = float(payload_kg)
        self.segment_s = float(segment_s)
        self.seed = int(seed)
        logs = [_filtered_positions(f, column_map, cutoff_hz) for f in self.files]
        self._build(logs, limits, int(passes), float(hold_s), float(blend_s))
        self._check_speed(limits)

    def _build(
        self, logs: list[np.ndarray], limits: np.ndarray, passes: int, hold_s: float, blend_s: float
    ) -> None:
        """The program on the grid, the spline through it and which log plays when."""
        rng = stream("twin.replay", self.seed)
        pieces = [logs[0][:1]]
        self._plays: list[tuple[float, int, float]] = []  # (start s, log, speed scale)
        for _ in range(passes):
            for k in rng.permutation(len(logs)):
                scale = float(rng.choice(self.speed_scales))
                log = logs[k]
                pieces.append(_move(pieces[-1][-1], log[0], limits, blend_s))
                start = sum(len(p) for p in pieces) - 1
                self._plays.append((start / GRID_HZ, int(k), scale))
                t_log = np.arange(len(log)) / GRID_HZ
                t_new = np.arange(1, int((t_log[-1] * GRID_HZ) / scale) + 1) * scale / GRID_HZ
                played = [np.interp(t_new, t_log, log[:, j]) for j in range(N_JOINTS)]
                pieces.append(np.stack(played, axis=1))
                hold = int(rng.uniform(0.0, hold_s) * GRID_HZ)
                if hold:
                    pieces.append(np.repeat(pieces[-1][-1:], hold, axis=0))
        pieces.append(_move(pieces[-1][-1], logs[0][0], limits, blend_s))  # back to the start
        q = np.concatenate(pieces)
        q[-1] = q[0]  # exactly periodic
        self.period_s = (len(q) - 1) / GRID_HZ
        self._starts = np.array([start for start, _, _ in self._plays])
        self._spline = CubicSpline(np.arange(len(q)) / GRID_HZ, q, bc_type="periodic")

    def _check_speed(self, limits: np.ndarray) -> None:
        t = np.arange(0.0, self.period_s, 1.0 / GRID_HZ)
        peak = np.abs(self._spline(t, 1)).max(axis=0)
        over = np.flatnonzero(peak > limits)
        if over.size:
            j = int(over[0])
            raise InputError(
                f"curriculum.speed_scales: joint {j} would replay at {peak[j]:.2f} rad/s, over "
                f"the arm's limit {limits[j]:.2f}; use smaller speed scales"
            )

    def __len__(self) -> int:
        return len(self._plays)

    def visit_at(self, t: float) -> int:
        return int(np.floor(t / self.segment_s + 1e-9))

    def _play_at(self, t: float) -> tuple[int, int, float]:
        """Which play of the program sounds at session time ``t``: (index, log, speed scale)."""
        local = t % self.period_s
        i = max(int(np.searchsorted(self._starts, local, side="right")) - 1, 0)
        return i, self._plays[i][1], self._plays[i][2]

    def scheduled(self, visit: int) -> ScheduledSegment:
        t0 = visit * self.segment_s
        _, log, scale = self._play_at(t0)
        segment = Segment(log, "replay", Path(self.files[log]).stem, tuple(range(N_JOINTS)),
                          scale, 1.0)  # fmt: skip
        ends = self.position(visit, np.array([t0, t0 + self.segment_s]))
        return ScheduledSegment(visit, segment, ends[0], ends[1], t0)

    def payload_kg(self, visit: int) -> float:
        return self.payload

    def position(self, visit: int, t: np.ndarray) -> np.ndarray:
        """Reference joint angles ``[len(t), 6]`` at session times ``t``."""
        return self._spline(np.asarray(t, dtype=float) % self.period_s)

    def reference(
        self, visit: int, t: np.ndarray, h: float = 1e-3
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and acceleration ``[len(t), 6]`` (the spline's own derivatives)."""
        local = np.asarray(t, dtype=float) % self.period_s
        return self._spline(local), self._spline(local, 1), self._spline(local, 2)
