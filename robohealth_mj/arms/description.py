"""Arm descriptions: a serial arm of any joint count as data, read from ``assets/<arm>/``.

A UR e-Series arm: UR's own parameter files (``ur_description/``, copied verbatim from UR's ROS 2
description package) give the kinematics, the link inertials and the joint limits; ``arm.yaml``
adds what they lack (rated payload, reach, UR's DH table for the independent checks). Any other
arm: ``arm.yaml`` alone, this project's own file written from the maker's published numbers
(``joints:``, base to tool: each joint's frame, limits and the link it moves), its provenance in
the folder's README. Light on purpose (numpy and yaml only): the torch- and MuJoCo-free runtime
reads an arm's ratings from here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import asset_dir, is_arm_file
from robohealth_mj.schema import JOINT_NAMES

DEFAULT_ARM = "ur5e"
# UR's link names in the description files, in the schema's joint order (joint i moves link i).
LINK_KEYS = ("shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3")
LINK_BODIES = tuple(f"{k}_link" for k in LINK_KEYS)
# UR's home: the arm upright, the tool pointing down (the model's start pose on every UR arm).
UR_HOME_POSE = np.array([-np.pi / 2, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0.0])


class _Loader(yaml.SafeLoader):
    """UR's joint-limit files write angles as ``!degrees 360.0``."""


_Loader.add_constructor("!degrees", lambda loader, node: math.radians(float(node.value)))


@dataclass(frozen=True)
class Link:
    """One link and the joint that moves it, as the maker's description gives them (URDF
    frames)."""

    origin_xyz: np.ndarray  # [3] the joint moving this link, in the parent link's frame
    origin_rpy: np.ndarray  # [3] URDF roll, pitch, yaw of that joint frame
    mass: float
    com: np.ndarray  # [3] centre of mass in the link frame
    inertia_rpy: np.ndarray  # [3] orientation of the inertia frame
    inertia: np.ndarray  # [3, 3] inertia tensor about the com, in the inertia frame
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))  # joint axis


@dataclass(frozen=True)
class ArmDescription:
    """Everything the builder, the curriculum and the ratings need about one arm."""

    name: str
    links: tuple[Link, ...]  # J links, base to tool (joint j moves link j)
    base_mass: float
    base_radius: float
    base_length: float
    rated_torque: np.ndarray  # [J] N m (the maker's effort limit)
    speed_limit: np.ndarray  # [J] rad/s
    position_limit: np.ndarray  # [J, 2] rad
    payload_kg: float
    reach_m: float
    dh: dict[str, np.ndarray] | None  # UR's DH table (d, a, alpha, mass [6]; com [6, 3]) or None
    source: Path
    joint_names: tuple[str, ...] = ()  # the driver's joint names, base to tool
    maker: str = "Universal Robots"
    torque_sensors: bool = False  # a torque sensor in every joint, reported by the controller
    flange_xyz: np.ndarray = field(default_factory=lambda: np.zeros(3))  # in the last link
    # The model's names and start pose where the loader fixes them (a UR arm: the schema's joint
    # names, UR's link names, UR's home); otherwise the driver's names, link<k>, the zero pose.
    model_keys: tuple[str, ...] = ()
    model_bodies: tuple[str, ...] = ()
    home: np.ndarray | None = None

    @property
    def n_joints(self) -> int:
        return len(self.links)

    @property
    def joint_keys(self) -> tuple[str, ...]:
        """The joints' names in the model and the graph: the schema's on a UR arm, the driver's
        on any other."""
        return self.model_keys or self.joint_names

    @property
    def link_bodies(self) -> tuple[str, ...]:
        """The model's body of each link: UR's link names, ``link<k>`` on any other arm."""
        return self.model_bodies or tuple(f"link{k}" for k in range(1, self.n_joints + 1))

    def home_pose(self) -> np.ndarray:
        """``[J]`` the pose the model starts in and the curriculum moves about: UR's home on a UR
        arm, else each joint in the middle of its range (zero where it turns without limit), so
        every joint has room to sweep both ways."""
        if self.home is not None:
            return self.home.copy()
        low, high = self.position_limit[:, 0], self.position_limit[:, 1]
        finite = np.isfinite(low) & np.isfinite(high)
        return np.where(finite, 0.5 * (np.where(finite, low, 0) + np.where(finite, high, 0)), 0.0)

    def ur_counterparts(self) -> tuple[str, ...]:
        """For each joint, the UR5e joint whose drive and motion it takes (the drive model and
        the curriculum are stated for the UR5e): on a UR arm its own; on another the last
        joint the UR's last (the tool joint), a joint rated at half the arm's largest torque or
        more a base joint's (shoulder lift), any other a wrist's (wrist 2)."""
        if self.joint_keys == JOINT_NAMES:
            return JOINT_NAMES
        big = self.rated_torque >= 0.5 * float(np.max(self.rated_torque))
        return tuple(
            "wrist_3" if j == self.n_joints - 1 else ("shoulder_lift" if big[j] else "wrist_2")
            for j in range(self.n_joints)
        )

    def ur_counterpart_index(self) -> list[int]:
        """:meth:`ur_counterparts` as indices into the UR's joints (what per-joint values stated
        for the UR are taken with)."""
        return [JOINT_NAMES.index(c) for c in self.ur_counterparts()]

    def ratings(self) -> dict[str, Any]:
        """The arm's identity and ratings, as manifests and checkpoints carry them."""
        return {
            "arm": self.name,
            "rated_torque_nm": [round(float(v), 6) for v in self.rated_torque],
            "speed_limit_rad_s": [round(float(v), 6) for v in self.speed_limit],
            "payload_kg": self.payload_kg,
            "reach_m": self.reach_m,
        }


def short_name(name: str) -> str:
    """The name to show and to put in run ids: a shipped arm's own, a file's stem."""
    return Path(name).stem if is_arm_file(name) else str(name)


def known_arms() -> tuple[str, ...]:
    """The arms shipped in ``assets/`` (each a folder with an ``arm.yaml``)."""
    return tuple(sorted(p.parent.name for p in asset_dir().glob("*/arm.yaml")))


def _read(path: Path) -> dict:
    try:
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=_Loader)
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror})") from None
    except yaml.YAMLError as e:
        raise InputError(f"{path}: not YAML ({str(e).splitlines()[0]})") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a mapping")
    return data


def _field(data: dict, path: Path, *keys: str) -> Any:
    """``data[k0][k1]...``, or a one-line error naming the file and the missing field."""
    node: Any = data
    for depth, key in enumerate(keys):
        if not isinstance(node, dict) or key not in node:
            raise InputError(f"{path}: missing field {'.'.join(keys[: depth + 1])}")
        node = node[key]
    return node


def _number(data: dict, path: Path, *keys: str) -> float:
    value = _field(data, path, *keys)
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{path}: field {'.'.join(keys)} is not a number ({value!r})") from None
    if not math.isfinite(number):
        raise InputError(f"{path}: field {'.'.join(keys)} is not finite ({value!r})")
    return number


def _vector(data: dict, path: Path, *keys: str, n: int) -> np.ndarray:
    value = _field(data, path, *keys)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{path}: field {'.'.join(keys)} is not numeric") from None
    if arr.shape[:1] != (n,) or not np.all(np.isfinite(arr)):
        raise InputError(f"{path}: field {'.'.join(keys)} needs {n} finite values")
    return arr


def _position_limit(lim: dict, path: Path, joint: tuple[str, str]) -> list[float]:
    """``[min, max]``, or unlimited where UR says the joint has none (a UR3e's wrist 3)."""
    if not _field(lim, path, *joint).get("has_position_limits", True):
        return [-math.inf, math.inf]
    return [_number(lim, path, *joint, "min_position"), _number(lim, path, *joint, "max_position")]


def load_arm(name: str = DEFAULT_ARM) -> ArmDescription:
    """The description of arm ``name`` (a folder of ``assets/``, or a user's ``.urdf`` file),
    validated field by field."""
    if is_arm_file(name):
        from robohealth_mj.arms.urdf import arm_from_urdf  # it builds on this module

        if not Path(name).is_file():
            raise InputError(f"arm={name}: no such URDF file")
        return arm_from_urdf(name)
    folder = asset_dir() / str(name)
    if not (folder / "arm.yaml").is_file():
        raise InputError(f"unknown arm {name!r}; known: {', '.join(known_arms())}")
    if not (folder / "ur_description").is_dir():
        return _load_chain(folder, str(name))
    return _load(folder, str(name))


_INERTIA = ("xx", "yy", "zz", "xy", "xz", "yz")


def _axis(item: dict, path: Path, *where: str) -> np.ndarray:
    """A joint's unit axis in its frame (``axis``, default z, as URDF's)."""
    if "axis" not in _field(item, path, *where):
        return np.array([0.0, 0.0, 1.0])
    axis = _vector(item, path, *where, "axis", n=3)
    norm = float(np.linalg.norm(axis))
    if not norm:
        raise InputError(f"{path}: field {'.'.join(where)}.axis is the zero vector")
    return axis / norm


@cache
def _load_chain(folder: Path, name: str) -> ArmDescription:
    """An arm described by this project's own ``arm.yaml`` (``joints:``, base to tool)."""
    path = folder / "arm.yaml"
    data = _read(path)
    joints = _field(data, path, "joints")
    if not isinstance(joints, list) or not joints:
        raise InputError(f"{path}: field joints needs a list, base to tool")
    links, limits = [], []
    for k, joint in enumerate(joints):
        where = ("joints", str(k))
        if not isinstance(joint, dict):
            raise InputError(f"{path}: field joints.{k} needs a mapping")
        item = {"joints": {str(k): joint}}
        i = {c: _number(item, path, *where, "inertia", c) for c in _INERTIA}
        links.append(Link(
            origin_xyz=_vector(item, path, *where, "origin_xyz", n=3),
            origin_rpy=_vector(item, path, *where, "origin_rpy", n=3),
            mass=_number(item, path, *where, "mass"),
            com=_vector(item, path, *where, "com", n=3),
            inertia_rpy=np.zeros(3),
            inertia=np.array([[i["xx"], i["xy"], i["xz"]], [i["xy"], i["yy"], i["yz"]],
                              [i["xz"], i["yz"], i["zz"]]]),
            axis=_axis(item, path, *where),
        ))  # fmt: skip
        limit = _field(item, path, *where, "limit")
        bounds = [_number(item, path, *where, "limit", c) if c in limit else default
                  for c, default in (("lower", -math.inf), ("upper", math.inf))]  # fmt: skip
        if ("lower" in limit) != ("upper" in limit):
            raise InputError(f"{path}: field joints.{k}.limit needs lower and upper, or neither")
        limits.append([*bounds, *(_number(item, path, *where, "limit", c)
                                  for c in ("velocity", "effort"))])  # fmt: skip
    lim = np.array(limits)
    names = tuple(str(n) for n in _field(data, path, "joint_names"))
    if len(names) != len(links):
        raise InputError(f"{path}: field joint_names needs {len(links)} names, one per joint")
    desc = ArmDescription(
        name=str(_field(data, path, "name")),
        links=tuple(links),
        base_mass=_number(data, path, "base", "mass"),
        base_radius=0.0,
        base_length=0.0,
        rated_torque=lim[:, 3],
        speed_limit=lim[:, 2],
        position_limit=lim[:, :2],
        payload_kg=_number(data, path, "payload_kg"),
        reach_m=_number(data, path, "reach_m"),
        dh=None,
        source=folder,
        joint_names=names,
        maker=str(_field(data, path, "maker")),
        torque_sensors=bool(data.get("torque_sensors", False)),
        flange_xyz=_vector(data, path, "flange_xyz", n=3),
    )
    return _checked(desc, name, path, path)


@cache
def _load(folder: Path, name: str) -> ArmDescription:
    ours = _read(folder / "arm.yaml")
    ur = folder / "ur_description"
    kin_path, phys_path, lim_path = (
        ur / "default_kinematics.yaml",
        ur / "physical_parameters.yaml",
        ur / "joint_limits.yaml",
    )
    kin, phys, lim = _read(kin_path), _read(phys_path), _read(lim_path)
    links = []
    for key in LINK_KEYS:
        k = ("kinematics", key)
        tensor = ("inertia_parameters", "tensor", key)
        i = {
            c: _number(phys, phys_path, *tensor, c)
            for c in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
        }
        cog = ("inertia_parameters", "center_of_mass", f"{key}_cog")
        rot = ("inertia_parameters", "rotation", key)
        links.append(
            Link(
                origin_xyz=np.array([_number(kin, kin_path, *k, c) for c in "xyz"]),
                origin_rpy=np.array(
                    [_number(kin, kin_path, *k, c) for c in ("roll", "pitch", "yaw")]
                ),
                mass=_number(phys, phys_path, "inertia_parameters", f"{key}_mass"),
                com=np.array([_number(phys, phys_path, *cog, c) for c in "xyz"]),
                inertia_rpy=np.array(
                    [_number(phys, phys_path, *rot, c) for c in ("roll", "pitch", "yaw")]
                ),
                inertia=np.array(
                    [
                        [i["ixx"], i["ixy"], i["ixz"]],
                        [i["ixy"], i["iyy"], i["iyz"]],
                        [i["ixz"], i["iyz"], i["izz"]],
                    ]
                ),
            )
        )
    limits = [("joint_limits", f"{j}_joint") for j in JOINT_NAMES]
    base = ("inertia_parameters", "links", "base")
    dh_path = folder / "arm.yaml"
    desc = ArmDescription(
        name=str(_field(ours, dh_path, "name")),
        links=tuple(links),
        base_mass=_number(phys, phys_path, "inertia_parameters", "base_mass"),
        base_radius=_number(phys, phys_path, *base, "radius"),
        base_length=_number(phys, phys_path, *base, "length"),
        rated_torque=np.array([_number(lim, lim_path, *j, "max_effort") for j in limits]),
        speed_limit=np.array([_number(lim, lim_path, *j, "max_velocity") for j in limits]),
        position_limit=np.array([_position_limit(lim, lim_path, j) for j in limits]),
        payload_kg=_number(ours, dh_path, "payload_kg"),
        reach_m=_number(ours, dh_path, "reach_m"),
        dh={
            **{k: _vector(ours, dh_path, "dh", k, n=6) for k in ("d", "a", "alpha", "mass")},
            "com": _vector(ours, dh_path, "dh", "com", n=6),
        },
        source=folder,
        joint_names=tuple(f"{j}_joint" for j in JOINT_NAMES),  # the UR driver's
        model_keys=JOINT_NAMES,
        model_bodies=LINK_BODIES,
        home=UR_HOME_POSE,
    )
    if desc.dh is not None and desc.dh["com"].shape != (6, 3):
        raise InputError(f"{dh_path}: field dh.com needs 6 rows of 3 values")
    return _checked(desc, name, dh_path, lim_path)


def _checked(desc: ArmDescription, name: str, path: Path, lim_path: Path) -> ArmDescription:
    """What every description must satisfy, whoever wrote it."""
    if desc.name != name:
        raise InputError(f"{path}: field name is {desc.name!r}, the folder says {name!r}")
    for what, values in (("effort", desc.rated_torque), ("velocity", desc.speed_limit)):
        if np.any(values <= 0):
            raise InputError(f"{lim_path}: every joint's {what} limit must be positive")
    if np.any(desc.position_limit[:, 0] >= desc.position_limit[:, 1]):
        raise InputError(f"{lim_path}: every joint's lower limit must lie below its upper")
    if any(link.mass <= 0 for link in desc.links):
        raise InputError(f"{path}: every link's mass must be positive")
    if desc.payload_kg <= 0 or desc.reach_m <= 0:
        raise InputError(f"{path}: payload_kg and reach_m must be positive")
    return desc
