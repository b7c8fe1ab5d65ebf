"""Which joint is which in a JointState message: the names an arm's driver gives its joints
(``conf/joint_names.yaml``: a preset, or the names, with the driver's ``tf_prefix``), found by
name in whatever order the message lists them."""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache

from omegaconf import DictConfig, ListConfig, OmegaConf

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import conf_dir
from robohealth_mj.schema import JOINT_NAMES


@cache
def _presets() -> DictConfig:
    """``conf/joint_names.yaml``, read once (a monitor asks for it once per arm)."""
    return OmegaConf.load(conf_dir() / "joint_names.yaml")


def joint_names(names: str | Sequence[str] = "schema", prefix: str = "") -> tuple[str, ...]:
    """The names, base to tool, of a preset in ``conf/joint_names.yaml`` or of a list, each
    with ``prefix`` before it; a bad value is one line naming ``ros2.joint_names``."""
    if isinstance(names, str):
        presets = _presets()
        if names not in presets:
            raise InputError(
                f"ros2.joint_names: unknown preset {names!r} (presets: {', '.join(presets)}; "
                "or a list of the arm's joint names, base to tool)"
            )
        names = presets[names]
    names = list(names) if isinstance(names, ListConfig | list | tuple) else names
    if len(names) < 2 or len(set(names)) != len(names):
        raise InputError(f"ros2.joint_names: need distinct names, base to tool, got {names}")
    return tuple(f"{prefix}{n}" for n in names)


def joint_order(names: Sequence[str], expected: Sequence[str] = JOINT_NAMES) -> list[int] | None:
    """Indices that put a message's arrays in the schema's joint order (``None``: already in
    it); a ``ValueError`` naming the first joint the message lacks."""
    names = list(names)
    if names == list(expected):
        return None
    missing = [n for n in expected if n not in names]
    if missing:
        raise ValueError(
            f"field 'name': joint '{missing[0]}' missing ({len(missing)} of {len(expected)}; "
            f"the message names {names})"
        )
    return [names.index(n) for n in expected]
