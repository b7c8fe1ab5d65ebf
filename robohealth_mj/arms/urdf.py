"""A user's own arm from its URDF (``arm=path/to/arm.urdf``): the serial chain from the root
link to the tool, each revolute joint's frame, axis and limits, each link's inertial, and the
ratings the URDF gives (``<limit effort velocity>``) or a ratings file beside it
(``<stem>.ratings.yaml``: ``payload_kg``, ``reach_m``, per joint ``effort`` and ``velocity``).

The same reader serves the scripts that write this project's own descriptions from a maker's
xacro (``studies/arms/``): ``<xacro:if>``/``<xacro:unless>`` blocks are taken or skipped by the
``choices`` given, and a block left unanswered that holds links or joints is refused. What a
serial arm cannot be is one line naming the element: a link with two moving children (a tree),
a link without an inertial, a joint that is neither revolute nor continuous, a joint with no
effort or velocity rating.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import yaml

from robohealth_mj.arms.chain import link_frames
from robohealth_mj.arms.description import ArmDescription, Link
from robohealth_mj.common.errors import InputError

XACRO = "{http://ros.org/wiki/xacro}"
XACRO_ALT = "{http://www.ros.org/wiki/xacro}"
MOVING = ("revolute", "continuous")


@dataclass
class ChainJoint:
    """One moving joint of the chain and the link it moves, as the file writes them."""

    name: str
    xyz: list[float]
    rpy: list[float]
    axis: list[float]
    limit: dict[str, str]  # the limit element's attributes, as written
    mass: float
    com: list[float]
    inertia: dict[str, float]  # ixx, iyy, izz, ixy, ixz, iyz


@dataclass
class Chain:
    joints: list[ChainJoint]
    flange: list[float]  # the fixed joint after the last link, in its frame (zero if none)
    base: dict  # the root link's inertial: mass, com


def _name(raw: str) -> str:
    return re.sub(r"\$\{[^}]*\}_?", "", raw)


def _numbers(text: str | None, where: str, path: Path) -> list[float]:
    try:
        values = [float(v) for v in (text or "0 0 0").split()]
    except ValueError:
        raise InputError(f"{path}: {where}: not three numbers ({text!r})") from None
    if len(values) != 3:
        raise InputError(f"{path}: {where}: not three numbers ({text!r})")
    return values


def _elements(node: ET.Element, choices: dict[str, bool], found: list[ET.Element]) -> None:
    for child in node:
        tag = child.tag.replace(XACRO_ALT, XACRO)
        if tag in (f"{XACRO}if", f"{XACRO}unless"):
            key = re.fullmatch(r"\$\{(\w+)\}", child.get("value", ""))
            if key is None or key[1] not in choices:
                inner: list[ET.Element] = []
                _elements(child, {}, inner)
                if inner:  # a block of links or joints needs its answer
                    raise ValueError(f"a condition this reader is not told: {child.get('value')}")
                continue
            if choices[key[1]] == (tag == f"{XACRO}if"):
                _elements(child, choices, found)
        elif tag in ("link", "joint"):
            found.append(child)
        else:
            _elements(child, choices, found)


def read_chain(
    path: Path, base: str | None = None, choices: dict[str, bool] | None = None
) -> Chain:
    """The chain from ``base`` (default: the root link, the one no joint moves) to the tool."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise InputError(f"{path}: not a readable URDF ({exc})") from None
    found: list[ET.Element] = []
    _elements(root, choices or {}, found)
    links = {_name(e.get("name", "")): e for e in found if e.tag == "link"}
    children: dict[str, list[ET.Element]] = {}
    for joint in (e for e in found if e.tag == "joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            raise InputError(f"{path}: joint '{_name(joint.get('name', ''))}': no parent or child")
        children.setdefault(_name(parent.get("link", "")), []).append(joint)
    if base is None:
        moved = {_name(j.find("child").get("link", "")) for js in children.values() for j in js}
        roots = [name for name in links if name not in moved]
        if len(roots) != 1:
            raise InputError(f"{path}: {len(roots)} root links ({', '.join(roots)}); one expected")
        base = roots[0]
    chain, flange, current = [], [0.0, 0.0, 0.0], base
    while children.get(current):
        moving = [j for j in children[current] if j.get("type") != "fixed"]
        if len(moving) > 1:  # fixed frames beside the next joint (a camera, a tool) are fine
            names = ", ".join(_name(j.get("name", "")) for j in moving)
            raise InputError(f"{path}: link '{current}' has {len(moving)} moving child joints "
                             f"({names}): a serial arm has one")  # fmt: skip
        joint = (moving or children[current])[0]
        name, kind = _name(joint.get("name", "")), joint.get("type")
        child = _name(joint.find("child").get("link", ""))
        origin = joint.find("origin")
        xyz = _numbers(origin.get("xyz") if origin is not None else None, f"joint '{name}'", path)
        rpy = _numbers(origin.get("rpy") if origin is not None else None, f"joint '{name}'", path)
        if kind == "fixed" and not chain:  # a mount (world -> base): the base moves down
            if any(rpy):
                raise InputError(f"{path}: joint '{name}': a tilted mount (rpy {rpy}); an arm "
                                 "standing upright only")  # fmt: skip
            base, current = child, child
            continue
        if kind == "fixed":
            flange = xyz
            break
        if kind not in MOVING:
            raise InputError(f"{path}: joint '{name}' is {kind}: an arm of revolute joints only")
        inertial = links.get(child).find("inertial") if child in links else None
        if inertial is None or inertial.find("mass") is None or inertial.find("inertia") is None:
            raise InputError(f"{path}: link '{child}': no <inertial> with mass and inertia")
        axis, limit = joint.find("axis"), joint.find("limit")
        direction = axis.get("xyz") if axis is not None else "1 0 0"  # URDF's default axis
        chain.append(ChainJoint(
            name=name, xyz=xyz, rpy=rpy, axis=_numbers(direction, f"joint '{name}' axis", path),
            limit={**(dict(limit.attrib) if limit is not None else {}), "type": kind},
            mass=float(inertial.find("mass").get("value")),
            com=_numbers(_origin(inertial), f"link '{child}' inertial", path),
            inertia={k: float(v) for k, v in inertial.find("inertia").attrib.items()},
        ))  # fmt: skip
        current = child
    if not chain:
        raise InputError(f"{path}: no revolute joint below link '{base}'")
    base_inertial = links[base].find("inertial") if base in links else None
    if base_inertial is None:  # the base does not move: its mass is only drawn
        return Chain(chain, flange, {"mass": 1.0, "com": [0.0, 0.0, 0.0]})
    mass = float(base_inertial.find("mass").get("value"))
    com = _numbers(_origin(base_inertial), f"link '{base}' inertial", path)
    return Chain(chain, flange, {"mass": mass, "com": com})


def _origin(element: ET.Element) -> str | None:
    origin = element.find("origin")
    return origin.get("xyz") if origin is not None else None


def arm_from_urdf(path: Path | str) -> ArmDescription:
    """A user's URDF as an arm description (``arm=path/to/arm.urdf``), rated from its
    ``<limit>`` elements or ``<stem>.ratings.yaml`` beside it."""
    path = Path(path)
    chain = read_chain(path)
    ratings_path = path.with_name(f"{path.stem}.ratings.yaml")
    ratings = yaml.safe_load(ratings_path.read_text()) if ratings_path.is_file() else {}
    if not isinstance(ratings, dict):
        raise InputError(f"{ratings_path}: expected a mapping")
    rated = ratings.get("joints", {}) or {}
    links, limits = [], []
    for joint in chain.joints:
        given = {**{k: joint.limit[k] for k in ("effort", "velocity") if k in joint.limit},
                 **(rated.get(joint.name) or {})}  # fmt: skip
        for key in ("effort", "velocity"):
            if not float(given.get(key, 0) or 0) > 0:
                where = f"{ratings_path.name} joints.{joint.name}.{key}"
                raise InputError(f"{path}: joint '{joint.name}': no {key} rating (its <limit "
                                 f"{key}=...> or {where})")  # fmt: skip
        bounded = joint.limit["type"] == "revolute" and "lower" in joint.limit
        low = float(joint.limit["lower"]) if bounded else -math.inf
        high = float(joint.limit.get("upper", math.inf)) if bounded else math.inf
        limits.append([low, high, float(given["velocity"]), float(given["effort"])])
        i = joint.inertia
        links.append(Link(
            origin_xyz=np.array(joint.xyz), origin_rpy=np.array(joint.rpy), mass=joint.mass,
            com=np.array(joint.com), inertia_rpy=np.zeros(3),
            inertia=np.array([[i.get("ixx", 0.0), i.get("ixy", 0.0), i.get("ixz", 0.0)],
                              [i.get("ixy", 0.0), i.get("iyy", 0.0), i.get("iyz", 0.0)],
                              [i.get("ixz", 0.0), i.get("iyz", 0.0), i.get("izz", 0.0)]]),
            axis=np.array(joint.axis) / np.linalg.norm(joint.axis),
        ))  # fmt: skip
    if "payload_kg" not in ratings:
        raise InputError(f"{path}: no rated payload: write payload_kg (and reach_m) in "
                         f"{ratings_path.name} beside it")  # fmt: skip
    lim = np.array(limits)
    desc = ArmDescription(
        name=str(path.resolve()), links=tuple(links), base_mass=chain.base["mass"], base_radius=0.0,
        base_length=0.0, rated_torque=lim[:, 3], speed_limit=lim[:, 2],
        position_limit=lim[:, :2], payload_kg=float(ratings["payload_kg"]),
        reach_m=float(ratings.get("reach_m", 0.0)) or 1.0, dh=None, source=path.parent,
        joint_names=tuple(j.name for j in chain.joints), maker="user",
        torque_sensors=bool(ratings.get("torque_sensors", False)),
        flange_xyz=np.array(chain.flange),
    )  # fmt: skip
    if "reach_m" not in ratings:  # the flange's distance from the first joint, arm at zero
        frames = link_frames(desc, np.zeros(desc.n_joints))
        tip = (frames[-1] @ np.append(desc.flange_xyz, 1.0))[:3]
        desc = replace(desc, reach_m=float(np.linalg.norm(tip)))
    return desc
