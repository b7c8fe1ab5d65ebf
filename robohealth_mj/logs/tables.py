"""A controller log's columns as arrays: CSV (comma, tab or space separated, as UR's RTDE recorder
and ur_rtde's write them) and parquet. Only the columns a map needs are read."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robohealth_mj.common.errors import InputError


@dataclass
class Table:
    source: str
    columns: dict[str, np.ndarray]  # name -> [rows] float64
    first_row: int  # what row 0 is called in messages (2 for a CSV under its header line)

    def row_name(self, i: int) -> str:
        return f"line {i + self.first_row}" if self.first_row > 1 else f"row {i + self.first_row}"


def read_header(path: Path) -> list[str]:
    if path.suffix == ".parquet":
        return list(_parquet().read_schema(path).names)
    with path.open(encoding="utf-8", errors="replace") as handle:
        line = handle.readline()
    return _split(line, _delimiter(line))


def read_table(path: Path, names: list[str], header: list[str] | None = None) -> Table:
    """The named columns of ``path``; a missing column or a non-number is one line naming the
    file, the column and the line (or row). ``header``: the column names of a CSV written without
    a header line (its first line is data)."""
    headerless = header is not None
    header = header if headerless else read_header(path)
    missing = [n for n in names if n not in header]
    if missing:
        raise InputError(f"{path}: column {missing[0]!r} missing ({len(missing)} missing in all)")
    if path.suffix == ".parquet":
        table = _parquet().read_table(path, columns=names)
        columns = {}
        for name in names:
            try:
                columns[name] = table.column(name).to_numpy(zero_copy_only=False).astype(float)
            except (TypeError, ValueError):
                raise InputError(f"{path}: column {name!r}: not numeric") from None
        return Table(str(path), columns, 1)
    return _read_csv(path, header, names, headerless)


def _read_csv(path: Path, header: list[str], names: list[str], headerless: bool) -> Table:
    with path.open(encoding="utf-8", errors="replace") as handle:
        first = handle.readline()
        delimiter = _delimiter(first)
        lines = ([first] if headerless else []) + handle.read().splitlines()
    first_line = 1 if headerless else 2
    index = [header.index(n) for n in names]
    values = np.empty((len(lines), len(names)))
    for row, line in enumerate(lines):
        cells = _split(line, delimiter)
        if len(cells) != len(header):
            if not line.strip() and row == len(lines) - 1:
                values = values[:row]
                break
            raise InputError(
                f"{path}: line {row + first_line}: {len(cells)} fields, the header has "
                f"{len(header)}"
            )
        for k, i in enumerate(index):
            try:
                values[row, k] = float(cells[i])
            except ValueError:
                raise InputError(
                    f"{path}: line {row + first_line}: column {names[k]!r}: {cells[i]!r} is not "
                    "a number"
                ) from None
    return Table(str(path), {n: values[:, k] for k, n in enumerate(names)}, first_line)


def _delimiter(line: str) -> str | None:
    return "," if "," in line else "\t" if "\t" in line else None  # None: any whitespace


def _split(line: str, delimiter: str | None) -> list[str]:
    return [c.strip() for c in line.rstrip("\r\n").split(delimiter)]


def _parquet():
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise InputError(
            "reading parquet needs pyarrow: pip install 'robohealth-mj[logs]'"
        ) from None
    return pq
