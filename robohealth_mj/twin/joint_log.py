"""A controller log's joint signals at its own rate, for identification (the monitor reads logs
resampled to the tick rate instead: :mod:`robohealth_mj.logs.convert`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.logs.convert import checked_column, checked_time, resolve_map
from robohealth_mj.logs.maps import CHANNEL_UNIT, UNITS
from robohealth_mj.logs.tables import read_header, read_table

J = schema.N_JOINTS


@dataclass
class JointLog:
    """One log's rows: ``[T]`` time, ``[T, 6]`` position, velocity, motor current (A) and the
    controller's model torque (N*m; None where the log has none)."""

    source: str
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    current: np.ndarray
    model_torque: np.ndarray | None

    @property
    def name(self) -> str:
        return Path(self.source).stem

    @property
    def rate_hz(self) -> float:
        return float(1.0 / np.median(np.diff(self.t)))


def read_joint_log(path: Path | str, column_map: str | None = None) -> JointLog:
    """Position, velocity, current and model torque of ``path`` through its column map (the
    shipped one whose columns it has); the map's ``effort`` must be a current."""
    path = Path(path)
    cmap, header = resolve_map(path, column_map)
    unit = cmap.units["effort"]
    if UNITS[unit][0] != "A":
        raise InputError(f"{path}: identification needs motor currents; map {cmap.name} gives "
                         f"effort in {unit}")  # fmt: skip
    moment = cmap.torque_constant[0] if cmap.fits_torque_constant else None
    names = list(cmap.needed())
    if moment is None and "target_moment_0" in (header or read_header(path)):
        moment = "target_moment_{j}"
    if moment:
        names += [moment.format(j=i) for i in cmap.joint_index if moment.format(j=i) not in names]
    table = read_table(path, names, header)
    rows = np.arange(len(table.columns[cmap.time]))
    if len(rows) < 10:
        raise InputError(f"{path}: {len(rows)} rows; identification needs a trajectory")
    t = checked_time(table, cmap, rows)

    def channel(col: str, si: str, factor: float = 1.0) -> np.ndarray:
        return np.stack(
            [checked_column(table, col.format(j=i), rows, si, factor) for i in cmap.joint_index],
            axis=1,
        )

    def signal(name: str) -> np.ndarray:  # the channel's own column (not a difference)
        return channel(cmap.channels[name][0], CHANNEL_UNIT[name], UNITS[cmap.units[name]][1])

    q, qd = signal("pos"), signal("vel")
    current = channel(cmap.channels["effort"][0], "A", UNITS[unit][1])
    torque = channel(moment, "N*m") if moment else None
    return JointLog(str(path), t - t[0], q, qd, current, torque)
