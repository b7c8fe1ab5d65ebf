"""Ready models by name: ``model=stock`` is the exported model shipped in the wheel
(``ready_models/stock.onnx``, its card ``stock.md``), ``file=sample`` the sample controller log
beside them, so that a user with a log or a live driver diagnoses it without training. A file of
that name where the command runs comes first."""

from __future__ import annotations

from pathlib import Path

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import ready_dir

SAMPLE = "sample"  # file=sample: the sample log, a UR5e's controller log in UR's RTDE layout
SAMPLE_FILE = "sample_ur5e.csv"


def ready_names() -> list[str]:
    """The ready models shipped, by name (``full``, ``stock``, ``ur_driver``)."""
    return sorted(p.stem for p in ready_dir().glob("*.onnx"))


def resolve_model(value: str | None) -> str | None:
    """A model file, or the ready model of that name; a bare name that is neither is refused
    naming the ready ones (a path that does not exist is left for the reader to name)."""
    if not value or Path(value).exists():
        return value
    shipped = ready_dir() / f"{value}.onnx"
    if shipped.is_file():
        return str(shipped)
    if "/" not in value and "." not in value:
        raise InputError(
            f"model={value}: no such file, and not a ready model "
            f"({', '.join(ready_names()) or 'none installed'})"
        )
    return value


def resolve_file(value: str | None) -> str | None:
    """``file=sample``: the shipped sample log, unless a file of that name is here."""
    if value == SAMPLE and not Path(value).exists():
        return str(ready_dir() / SAMPLE_FILE)
    return value
