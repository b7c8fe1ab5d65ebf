"""Write ``assets/xarm7/arm.yaml`` from UFACTORY's description of the xArm7 (``xArm-Developer/
xarm_ros2``, branch humble, ``xarm_description``, BSD-3-Clause): the joint frames from
``config/kinematics/default/xarm7_default_kinematics.yaml``, the link inertials from
``config/link_inertial/xarm7_type7_HT_BR2.yaml`` (the file the description picks by default),
each joint's axis, effort and speed, and the position limits (the macro's default parameters,
``joint1_lower_limit:=${-2.0*pi}`` ...) from ``urdf/xarm7/xarm7.urdf.xacro``; payload and reach
from UFACTORY's datasheet.

    bash studies/arms/fetch_xarm7.sh   # the three files at the cited commit, into outputs/xarm7/
    python studies/arms/write_xarm7.py outputs/xarm7
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import yaml
from urdf_chain import ChainJoint, description_yaml

from robohealth_mj.common.atomic import atomic_write_text

COMMIT = "5109131e7870c7d6e1075042d531e659d072cdb0"
OUT = Path(__file__).resolve().parents[2] / "assets" / "xarm7" / "arm.yaml"


def _limits(xacro: str) -> list[dict[str, float]]:
    """Per joint, base to tool: the macro's default bounds, the effort and the speed."""
    defaults = {k: float(eval(v, {"__builtins__": {}}, {"pi": math.pi}))  # numbers and pi only
                for k, v in re.findall(r"(\w+_limit):=\$\{([-0-9.*pi ]+)\}", xacro)}  # fmt: skip
    found = re.findall(r'lower="\$\{(\w+)\}"\s*upper="\$\{(\w+)\}"\s*effort="([^"]+)"\s*'
                       r'velocity="([^"]+)"', xacro)  # fmt: skip
    return [{"lower": round(defaults[lo], 6), "upper": round(defaults[hi], 6),
             "velocity": float(v), "effort": float(e)} for lo, hi, e, v in found]  # fmt: skip


def main(folder: Path) -> None:
    kinematics = yaml.safe_load((folder / "xarm7_default_kinematics.yaml").read_text())
    inertials = yaml.safe_load((folder / "xarm7_type7_HT_BR2.yaml").read_text())
    xacro = (folder / "xarm7.urdf.xacro").read_text()
    base = re.search(r'link_base">\s*<inertial>\s*<origin xyz="([^"]+)"[^/]*/>\s*'
                     r'<mass value="([^"]+)"', xacro)  # fmt: skip
    chain = []
    for k in range(1, 8):
        joint, link = kinematics["kinematics"][f"joint{k}"], inertials[f"link{k}"]
        chain.append(ChainJoint(
            name=f"joint{k}",
            xyz=[float(joint[c]) for c in "xyz"],
            rpy=[float(joint[c]) for c in ("roll", "pitch", "yaw")],
            axis=[0.0, 0.0, 1.0],  # every joint of the xacro: axis xyz="0 0 1"
            limit={}, mass=float(link["mass"]),
            com=[float(link["origin"][c]) for c in "xyz"],
            inertia={key: float(value) for key, value in link["inertia"].items()},
        ))  # fmt: skip
    limits = _limits(xacro)
    assert len(limits) == 7 and xacro.count('<axis xyz="0 0 1" />') == 7, "the xacro changed"
    header = [
        "UFACTORY xArm7 (`arm=xarm7`): this project's own description, written by",
        "studies/arms/write_xarm7.py from xArm-Developer/xarm_ros2's xarm_description",
        f"(branch humble, BSD-3-Clause) at commit {COMMIT};",
        "payload and reach from UFACTORY's datasheet. Every number's origin: README.md.",
    ]
    fields = {
        "name": "xarm7", "maker": "UFACTORY", "payload_kg": "3.5", "reach_m": "0.7",
        "joint_names": f"[{', '.join(j.name for j in chain)}]   # xarm_ros2's",
        "torque_sensors": "false   # none: the driver's effort is from the motor current",
    }  # fmt: skip
    base_data = {"mass": float(base[2]), "com": [float(v) for v in base[1].split()]}
    atomic_write_text(
        OUT, description_yaml(header, fields, chain, limits, [0.0, 0.0, 0.0], base_data)
    )
    print(f"-> {OUT}")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
