"""The serial chain of a maker's URDF or xacro file, read as XML: each movable joint base to
tool (its frame, axis and limit attributes) with the inertial of the link it moves, and the fixed
joint to the flange. Shared by the scripts that write this project's own arm descriptions from
published numbers (``write_iiwa14.py``, ``write_gen3.py``).

A xacro's ``<xacro:if>`` / ``<xacro:unless>`` blocks are taken or skipped by the ``choices``
given (``{"vision": True}`` for ``value="${vision}"``); a ``${prefix}`` or ``${robot_name}`` in a
name is dropped. Nothing else of xacro is evaluated: a value that is an expression stays text,
for the caller to replace from the maker's other files.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

XACRO = "{http://ros.org/wiki/xacro}"
XACRO_ALT = "{http://www.ros.org/wiki/xacro}"


@dataclass
class ChainJoint:
    name: str
    xyz: list[float]
    rpy: list[float]
    axis: list[float]
    limit: dict[str, str]  # the limit element's attributes, as written
    mass: float
    com: list[float]
    inertia: dict[str, float]  # ixx, iyy, izz, ixy, ixz, iyz


def _numbers(text: str | None) -> list[float]:
    return [float(v) for v in (text or "0 0 0").split()]


def _name(raw: str) -> str:
    return re.sub(r"\$\{[^}]*\}_?", "", raw)


def _elements(node: ET.Element, choices: dict[str, bool], found: list[ET.Element]) -> None:
    for child in node:
        tag = child.tag.replace(XACRO_ALT, XACRO)
        if tag in (f"{XACRO}if", f"{XACRO}unless"):
            key = re.fullmatch(r"\$\{(\w+)\}", child.get("value", ""))
            if key is None or key[1] not in choices:
                inner: list[ET.Element] = []
                _elements(child, {}, inner)  # a block of links or joints needs its answer
                if inner:
                    raise ValueError(f"a condition this reader is not told: {child.get('value')}")
                continue
            if choices[key[1]] == (tag == f"{XACRO}if"):
                _elements(child, choices, found)
        elif tag in ("link", "joint"):
            found.append(child)
        else:
            _elements(child, choices, found)


def read_chain(
    path: Path, base: str, choices: dict[str, bool] | None = None
) -> tuple[list[ChainJoint], list[float], dict]:
    """The movable joints from ``base`` to the tool, the flange's offset in the last link (the
    fixed joint after it, zero if none) and the base link's inertial."""
    found: list[ET.Element] = []
    _elements(ET.parse(path).getroot(), choices or {}, found)
    links = {_name(e.get("name", "")): e for e in found if e.tag == "link"}
    joints = {_name(e.find("parent").get("link")): e for e in found
              if e.tag == "joint" and e.find("parent") is not None}  # fmt: skip
    chain, flange, current = [], [0.0, 0.0, 0.0], base
    while current in joints:
        joint = joints[current]
        child = _name(joint.find("child").get("link"))
        origin = joint.find("origin")
        if joint.get("type") == "fixed":
            flange = _numbers(origin.get("xyz") if origin is not None else None)
            break
        inertial = links[child].find("inertial")
        chain.append(ChainJoint(
            name=_name(joint.get("name")),
            xyz=_numbers(origin.get("xyz")), rpy=_numbers(origin.get("rpy")),
            axis=_numbers(joint.find("axis").get("xyz")),
            limit=dict(joint.find("limit").attrib) if joint.find("limit") is not None else {},
            mass=float(inertial.find("mass").get("value")),
            com=_numbers(inertial.find("origin").get("xyz")),
            inertia={k: float(v) for k, v in inertial.find("inertia").attrib.items()},
        ))  # fmt: skip
        current = child
    base_inertial = links[base].find("inertial")
    base_data = {"mass": float(base_inertial.find("mass").get("value")),
                 "com": _numbers(base_inertial.find("origin").get("xyz"))}  # fmt: skip
    return chain, flange, base_data


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
