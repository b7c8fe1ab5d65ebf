"""A controller log -> GraphSamples at the tick rate, joint channels only, no ground truth.

Resampling: the schema's joint channels are instantaneous (the simulator reads them at each
tick's last physics step; nothing of them is averaged), so every channel is the log's value at
the tick's instant, interpolated linearly between the two log rows around it (exact for a
signal linear between rows; at 125-500 Hz the next row is 2-8 ms away). A tick whose two rows
are further apart than ``gap_s`` (default three log periods) is not made: the sample indices
jump there, so no window crosses a gap. The sensor package's channels, the averaged ones, are
absent on a stock arm and stay zero. Every sample is labelled healthy and inactive: a log has
no ground truth.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.jsonl import node_features
from robohealth_mj.logs.maps import UNITS, ColumnMap, detect_map, load_map
from robohealth_mj.logs.tables import Table, read_header, read_table

LOG_SUFFIXES = (".csv", ".parquet")
TICK_HZ = 20.0  # the GraphSample rate the models are trained at (conf/record.yaml)
RATE_HZ = (10.0, 500.0)  # the log rates accepted (5 % either side for clock jitter)
# What no joint of a 6-axis cobot reports; a value beyond means a wrong unit or column.
LIMITS = {"rad": 2 * np.pi * 1.05, "rad/s": 4 * np.pi, "A": 100.0, "N*m": 1000.0}
HINTS = {"rad": "degrees logged as radians?", "rad/s": "degrees per second as radians?",
         "A": "milliamperes logged as amperes?", "N*m": "a wrong column?"}  # fmt: skip


def is_log(path: Path | str) -> bool:
    return Path(path).suffix.lower() in LOG_SUFFIXES and Path(path).is_file()


@dataclass
class LogSession:
    """One session of a log at the tick rate."""

    run_id: str
    t: np.ndarray  # [T] seconds, the log's clock
    sample_index: np.ndarray  # [T] ticks since the session's first row
    state: np.ndarray  # [T, 6, 5] the schema's joint channels, SI
    stats: dict = field(default_factory=dict)


def convert_log(
    path: Path | str,
    column_map: str | Path | ColumnMap | None = None,
    tick_hz: float = TICK_HZ,
    gap_s: float | None = None,
) -> tuple[ColumnMap, list[LogSession]]:
    """Read ``path`` through ``column_map`` (a name, a YAML path, or None: the shipped map whose
    columns the log has) and resample every session to ``tick_hz``."""
    path = Path(path)
    cmap, header = resolve_map(path, column_map)
    table = read_table(path, cmap.needed(), header)
    rows = np.arange(len(table.columns[cmap.time]))
    if not len(rows):
        raise InputError(f"{path}: no rows")
    sessions = []
    if cmap.session:
        keys = table.columns[cmap.session]
        for key in dict.fromkeys(keys.tolist()):
            label = int(key) if float(key).is_integer() else key
            sessions.append((f"{path.stem}-{cmap.session}{label}", rows[keys == key]))
    else:
        sessions.append((path.stem, rows))
    return cmap, [_session(table, cmap, run_id, idx, tick_hz, gap_s) for run_id, idx in sessions]


def resolve_map(
    path: Path, column_map: str | Path | ColumnMap | None = None
) -> tuple[ColumnMap, list[str] | None]:
    """The map ``path`` reads through, its optional channels the log lacks dropped, and the
    column names of a table with no header line (None where the file has one)."""
    if not path.is_file():
        raise FileNotFoundError(f"no log at {path}")
    first = read_header(path)
    if isinstance(column_map, ColumnMap):
        cmap = column_map
    elif column_map is None:
        cmap = detect_map(first, str(path))
    else:
        cmap = load_map(column_map)
    header = cmap.header_of(first)
    try:
        cmap = cmap.for_header(header)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    return cmap, (header if header is not first else None)


def log_sensing(path: Path | str, column_map: str | Path | ColumnMap | None = None) -> str:
    """The sensing profile a log is read with: the channels its columns give (``stock`` for a
    full RTDE log, ``stock_reduced`` for one without the target position, ...)."""
    return resolve_map(Path(path), column_map)[0].sensing()


def _session(
    table: Table, cmap: ColumnMap, run_id: str, idx: np.ndarray, tick_hz: float, gap_s: float | None
) -> LogSession:
    src = table.source
    t = checked_time(table, cmap, idx)
    dt = np.diff(t)
    if len(t) < 2:
        raise InputError(f"{src}: session {run_id}: one row; a log needs at least two")
    period = float(np.median(dt))
    rate = 1.0 / period
    if not RATE_HZ[0] * 0.95 <= rate <= RATE_HZ[1] * 1.05:
        raise InputError(
            f"{src}: column {cmap.time!r}: {rate:.4g} Hz (median step {period:.4g} s) is outside "
            f"{RATE_HZ[0]:g}-{RATE_HZ[1]:g} Hz: is the time in seconds?"
        )
    k_t = _torque_constants(table, cmap, idx)
    state = np.zeros((len(t), schema.N_JOINTS, len(schema.STATE_FEATURES)))
    for c, channel in enumerate(schema.STATE_FEATURES):
        if channel not in cmap.channels:  # a channel this log lacks: zero, as the profile says
            continue
        unit = cmap.units[channel]
        si, factor = UNITS[unit]
        for j in range(schema.N_JOINTS):
            cols = cmap.columns(channel, j)
            values = [checked_column(table, col, idx, si, factor) for col in cols]
            series = values[0] - values[1] if len(values) == 2 else values[0]
            state[:, j, c] = series * (k_t[j] if si == "A" else 1.0)
    gap = 3.0 * period if gap_s is None else float(gap_s)
    ticks = np.arange(0.0, t[-1] - t[0] + 1e-9, 1.0 / tick_hz)
    at = t[0] + ticks
    right = np.clip(np.searchsorted(t, at, side="left"), 1, len(t) - 1)
    keep = (t[right] - t[right - 1] <= gap) | np.isclose(at, t[right - 1])
    at, index = at[keep], np.flatnonzero(keep)
    flat = state.reshape(len(t), -1)
    out = np.stack([np.interp(at, t, flat[:, k]) for k in range(flat.shape[1])], axis=-1)
    stats = {
        "rows": len(t),
        "rate_hz": round(rate, 3),
        "ticks": len(at),
        "ticks_in_gaps": int((~keep).sum()),
        "torque_constant_nm_per_a": None if k_t is None else [round(float(v), 4) for v in k_t],
        "sensing": cmap.sensing(),
        "dropped": dict(cmap.dropped),
    }
    return LogSession(run_id, at, index.astype(np.int64), out.reshape(len(at), *state.shape[1:]),
                      stats)  # fmt: skip


def checked_time(table: Table, cmap: ColumnMap, idx: np.ndarray) -> np.ndarray:
    """The time column's rows ``idx``, refused at the first row not after the one before."""
    t = checked_column(table, cmap.time, idx, None)
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        k = idx[back[0] + 1]
        raise InputError(
            f"{table.source}: column {cmap.time!r}: {table.row_name(k)}: time "
            f"{t[back[0] + 1]:.6g} is not after the row before ({t[back[0]]:.6g}): time must "
            "increase"
        )
    return t


def checked_column(
    table: Table, column: str, idx: np.ndarray, si: str | None, factor: float = 1.0
) -> np.ndarray:
    """The column's rows ``idx`` in SI, refused at the first NaN or value no arm reports."""
    values = table.columns[column][idx] * factor
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        row = table.row_name(int(idx[bad[0]]))
        raise InputError(f"{table.source}: column {column!r}: {row}: not a finite number")
    if si in LIMITS:
        over = np.flatnonzero(np.abs(values) > LIMITS[si])
        if over.size:
            row = table.row_name(int(idx[over[0]]))
            raise InputError(
                f"{table.source}: column {column!r}: {row}: {values[over[0]]:.6g} {si} is beyond "
                f"±{LIMITS[si]:.4g} {si} ({HINTS[si]})"
            )
    return values


def _torque_constants(table: Table, cmap: ColumnMap, idx: np.ndarray) -> np.ndarray | None:
    """N*m per A per joint: the map's numbers, or the least-squares fit of the controller's model
    torque on its target current over the session."""
    if cmap.torque_constant is None:
        return None
    if not cmap.fits_torque_constant:
        return np.asarray(cmap.torque_constant, float)
    moment_col, current_col = cmap.torque_constant
    out = np.empty(schema.N_JOINTS)
    for j, name in enumerate(cmap.joint_index):
        moment = checked_column(table, moment_col.format(j=name), idx, "N*m")
        current = checked_column(table, current_col.format(j=name), idx, "A")
        energy = float(current @ current)
        if energy < 1e-9 * len(current):
            raise InputError(
                f"{table.source}: column {current_col.format(j=name)!r}: the target current is "
                "zero throughout, so the torque constant cannot be fitted: give six numbers as "
                f"torque_constant in the column map ({cmap.source})"
            )
        out[j] = float(moment @ current) / energy
    return out


def session_samples(session: LogSession) -> Iterator[schema.GraphSample]:
    """One log session's GraphSamples (healthy, inactive labels; sensor channels zero)."""
    no_sensor = np.zeros((schema.N_JOINTS, len(schema.SENSOR_FEATURES)))
    for k in range(len(session.t)):
        x = node_features(session.state[k], no_sensor).astype(np.float32)
        yield schema.GraphSample(
            session.run_id, int(session.sample_index[k]), float(session.t[k]), x,
            schema.FaultLabel(), dict(schema.UNLABELLED_SEGMENT),
        )  # fmt: skip


def log_samples(
    path: Path | str, column_map: str | Path | ColumnMap | None = None
) -> Iterator[schema.GraphSample]:
    """GraphSamples of a controller log, every session in turn."""
    _, sessions = convert_log(path, column_map)
    for session in sessions:
        yield from session_samples(session)
