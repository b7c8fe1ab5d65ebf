"""Column maps: which columns of a controller log make each joint channel, in which units.

A map is YAML (``conf/logmap/<name>.yaml``, or any file): the time column, an optional session
column, the index that fills ``{j}`` in column names for each joint, per schema channel a column
or ``[a, b]`` for ``a - b``, per channel a unit, and the torque constant for channels in amperes.
A map may name the channels a log can lack (``optional``): such a log is read with the sensing
profile of the channels it has (:func:`ColumnMap.for_header`), and names the columns of a table
written without a header line (``header``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import conf_dir

MAPS_DIR = conf_dir() / "logmap"

# Unit -> (SI unit, factor to it). Amperes become N*m through the torque constant.
UNITS: dict[str, tuple[str, float]] = {
    "rad": ("rad", 1.0),
    "deg": ("rad", np.pi / 180.0),
    "rad/s": ("rad/s", 1.0),
    "deg/s": ("rad/s", np.pi / 180.0),
    "N*m": ("N*m", 1.0),
    "A": ("A", 1.0),
    "mA": ("A", 1e-3),
}
# The SI unit each schema channel is in.
CHANNEL_UNIT = {"pos": "rad", "vel": "rad/s", "effort": "N*m", "pos_error": "rad",
                "effort_residual": "N*m"}  # fmt: skip


@dataclass(frozen=True)
class ColumnMap:
    name: str
    source: str  # the YAML it came from (for messages)
    time: str
    session: str | None
    joint_index: tuple[Any, ...]
    channels: dict[str, tuple[str, ...]]  # channel -> (column,) or (a, b) for a - b, with {j}
    units: dict[str, str]
    torque_constant: tuple[float, ...] | tuple[str, str] | None  # numbers, or fit columns
    optional: tuple[str, ...] = ()  # channels a log may lack (it is then read without them)
    header: tuple[str, ...] | None = None  # the column names of a table with no header line
    dropped: dict[str, str] = field(default_factory=dict)  # channel -> why (for_header)

    def columns(self, channel: str, joint: int) -> tuple[str, ...]:
        return tuple(c.format(j=self.joint_index[joint]) for c in self.channels[channel])

    def needed(self) -> list[str]:
        """Every column this map reads, in a stable order."""
        names = [self.time, *([self.session] if self.session else [])]
        for channel in self.channels:
            for j in range(schema.N_JOINTS):
                names += self.columns(channel, j)
        if self.fits_torque_constant:
            names += [c.format(j=i) for i in self.joint_index for c in self.torque_constant]
        return list(dict.fromkeys(names))

    @property
    def fits_torque_constant(self) -> bool:
        tc = self.torque_constant
        return tc is not None and len(tc) == 2 and all(isinstance(c, str) for c in tc)

    def matches(self, header: Iterable[str]) -> bool:
        """Whether a log with these columns reads through this map (optional channels aside)."""
        return bool(self.for_header(header, strict=False))

    def header_of(self, first_line: list[str]) -> list[str]:
        """The column names of a table whose first line is ``first_line``: that line, or this
        map's ``header`` where the line is numbers of as many fields (a table with no header)."""
        if self.header and len(first_line) == len(self.header) and _numbers(first_line):
            return list(self.header)
        return first_line

    def for_header(self, header: Iterable[str], strict: bool = True) -> ColumnMap | None:
        """This map for a log with columns ``header``: each optional channel whose columns the
        log lacks is dropped (``dropped`` says why). A required column missing: an InputError
        naming it (``strict``) or None."""
        have = set(header)
        dropped = {}
        for channel in self.optional:
            gone = [c for j in range(schema.N_JOINTS) for c in self.columns(channel, j)
                    if c not in have]  # fmt: skip
            if gone:
                dropped[channel] = f"column {gone[0]!r} missing"
        kept = replace(
            self,
            channels={k: v for k, v in self.channels.items() if k not in dropped},
            dropped=dropped,
        )
        missing = [c for c in kept.needed() if c not in have]
        if not missing:
            return kept
        if strict:
            raise InputError(f"column {missing[0]!r} missing ({len(missing)} missing in all)")
        return None

    def sensing(self) -> str:
        """The sensing profile of the channels this map reads (no sensor package): the shipped
        profile whose joint channels are exactly these."""
        from robohealth_mj.data.sensing import stock_profile_for

        return stock_profile_for(tuple(self.channels), self.source)


def _numbers(cells: list[str]) -> bool:
    try:
        [float(c) for c in cells]
    except ValueError:
        return False
    return bool(cells)


def _fail(source: str, key: str, why: str) -> InputError:
    return InputError(f"{source}: key '{key}': {why}")


def load_map(name_or_path: str | Path) -> ColumnMap:
    """A map by name (``conf/logmap/<name>.yaml``) or by path; one-line errors name the key."""
    path = Path(name_or_path)
    if not path.suffix:
        path = MAPS_DIR / f"{name_or_path}.yaml"
        if not path.is_file():
            known = sorted(p.stem for p in MAPS_DIR.glob("*.yaml"))
            raise InputError(f"no column map {str(name_or_path)!r}: one of {known} or a YAML path")
    try:
        raw = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise InputError(f"{path}: not YAML ({str(exc).splitlines()[0]})") from None
    src = str(path)
    if not isinstance(raw, dict):
        raise InputError(f"{src}: a column map is a mapping")
    for key in ("time", "joint_index", "channels", "units"):
        if key not in raw:
            raise _fail(src, key, "missing")
    index = raw["joint_index"]
    if not isinstance(index, list) or len(index) != schema.N_JOINTS:
        raise _fail(src, "joint_index", f"{schema.N_JOINTS} values, one per joint")
    channels: dict[str, tuple[str, ...]] = {}
    for channel, spec in (raw["channels"] or {}).items():
        if channel not in schema.STATE_FEATURES:
            raise _fail(src, f"channels.{channel}", f"unknown (one of {list(CHANNEL_UNIT)})")
        cols = (spec,) if isinstance(spec, str) else tuple(spec or ())
        if len(cols) not in (1, 2) or not all(isinstance(c, str) for c in cols):
            raise _fail(src, f"channels.{channel}", "a column name or [a, b] for a - b")
        channels[channel] = cols
    missing = [c for c in schema.STATE_FEATURES if c not in channels]
    if missing:
        raise _fail(src, "channels", f"{missing} missing: a stock model reads all five")
    optional = tuple(raw.get("optional") or ())
    unknown = [c for c in optional if c not in channels]
    if unknown:
        raise _fail(src, "optional", f"{unknown[0]!r} is not one of the map's channels")
    header = raw.get("header")
    if header is not None and (
        not isinstance(header, list) or not all(isinstance(c, str) for c in header)
    ):
        raise _fail(src, "header", "the column names, in order, of a table with no header line")
    units = dict(raw["units"] or {})
    for channel in channels:
        unit = units.get(channel)
        if unit not in UNITS:
            raise _fail(src, f"units.{channel}", f"{unit!r} is not one of {list(UNITS)}")
        si = UNITS[unit][0]
        if si != CHANNEL_UNIT[channel] and not (si == "A" and CHANNEL_UNIT[channel] == "N*m"):
            raise _fail(src, f"units.{channel}", f"{unit} cannot be {CHANNEL_UNIT[channel]}")
    tc = raw.get("torque_constant")
    if isinstance(tc, dict) and "fit" in tc:
        tc = tuple(tc["fit"])
        if len(tc) != 2 or not all(isinstance(c, str) for c in tc):
            raise _fail(src, "torque_constant.fit", "[model torque column, current column]")
    elif tc is not None:
        if not isinstance(tc, list) or len(tc) != schema.N_JOINTS:
            raise _fail(src, "torque_constant", f"{schema.N_JOINTS} numbers (N*m per A) or fit")
        tc = tuple(float(v) for v in tc)
    if tc is None and any(UNITS[units[c]][0] == "A" for c in channels):
        raise _fail(src, "torque_constant", "needed: a channel is in amperes")
    return ColumnMap(
        name=str(raw.get("name", path.stem)),
        source=src,
        time=str(raw["time"]),
        session=raw.get("session"),
        joint_index=tuple(index),
        channels=channels,
        units=units,
        torque_constant=tc,
        optional=optional,
        header=tuple(header) if header else None,
    )


def detect_map(header: Iterable[str], source: str) -> ColumnMap:
    """The shipped map whose columns the log has (the first, by name); ``header`` is the log's
    first line (a map with a ``header`` of its own reads a table that has none)."""
    header = list(header)
    for path in sorted(MAPS_DIR.glob("*.yaml")):
        cmap = load_map(path)
        if cmap.matches(cmap.header_of(header)):
            return cmap
    raise InputError(
        f"{source}: no column map fits its columns ({', '.join(header[:6])}, ...): "
        "pass one (--map NAME_OR_YAML)"
    )
