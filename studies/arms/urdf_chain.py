"""What the scripts that write this project's own arm descriptions from a maker's published
numbers share (``write_iiwa14.py``, ``write_gen3.py``, ``write_xarm7.py``): the package's URDF
and xacro chain reader (:mod:`robohealth_mj.arms.urdf`, which also reads a user's ``arm=*.urdf``)
and the writer of ``arm.yaml``. A xacro's ``<xacro:if>`` / ``<xacro:unless>`` blocks are taken
or skipped by the ``choices`` given; nothing else of xacro is evaluated (a value that is an
expression stays text, for the caller to replace from the maker's other files).
"""

from __future__ import annotations

from robohealth_mj.arms.urdf import Chain, ChainJoint, read_chain

__all__ = ["Chain", "ChainJoint", "description_yaml", "read_chain"]


def description_yaml(
    header: list[str], fields: dict[str, str], chain: list[ChainJoint], limits: list[dict],
    flange: list[float], base: dict,
) -> str:  # fmt: skip
    """This project's ``arm.yaml`` (``robohealth_mj/arms/description.py`` reads it) from a chain
    and the limits the caller settled per joint (``lower``/``upper`` absent: unlimited)."""
    lines = [*(f"# {h}" for h in header), *(f"{k}: {v}" for k, v in fields.items())]
    lines.append(f"base: {{mass: {base['mass']}, com: {base['com']}}}")
    lines.append("joints:")
    for joint, limit in zip(chain, limits, strict=True):
        moments = ", ".join(f"{c}: {joint.inertia['i' + c]}"
                            for c in ("xx", "yy", "zz", "xy", "xz", "yz"))  # fmt: skip
        bounds = ", ".join(f"{k}: {v}" for k, v in limit.items())
        lines += [f"  - origin_xyz: {joint.xyz}", f"    origin_rpy: {joint.rpy}",
                  f"    axis: {joint.axis}", f"    limit: {{{bounds}}}",
                  f"    mass: {joint.mass}", f"    com: {joint.com}",
                  f"    inertia: {{{moments}}}"]  # fmt: skip
    lines.append(
        f"flange_xyz: {flange}   # the flange in the last link: where a payload is carried"
    )
    return "\n".join(lines) + "\n"
