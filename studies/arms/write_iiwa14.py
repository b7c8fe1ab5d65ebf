"""Write ``assets/iiwa14/arm.yaml`` from the community description of the KUKA LBR iiwa 14 R820
(``lbr-stack/lbr_fri_ros2_stack``, ``lbr_description/urdf/iiwa14/``, Apache-2.0): its joint
frames, axes and link inertials, read from the xacro's numbers; the rated torques from KUKA's
datasheet (the description's efforts are a placeholder 200 N m on every joint).

    bash studies/arms/fetch_iiwa14.sh   # the xacro and the joint limits at the cited commit
    python studies/arms/write_iiwa14.py outputs/iiwa14/iiwa14_description.xacro \
        outputs/iiwa14/joint_limits.yaml
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import yaml

from robohealth_mj.common.atomic import atomic_write_text

COMMIT = "218d723f817c61314988833611effddc5333ca6c"
# KUKA's LBR iiwa 14 R820 datasheet: maximum torque per axis (N m), rated payload, reach.
RATED_TORQUE_NM = [320.0, 320.0, 176.0, 176.0, 110.0, 40.0, 40.0]
PAYLOAD_KG, REACH_M = 14.0, 0.82
OUT = Path(__file__).resolve().parents[2] / "assets" / "iiwa14" / "arm.yaml"


def _numbers(text: str) -> list[float]:
    return [float(v) for v in text.split()]


def main(xacro: Path, limits_file: Path) -> None:
    text = xacro.read_text()
    limits = yaml.safe_load(limits_file.read_text())
    links = {
        m["name"]: m
        for m in re.finditer(
            r'<link name="\$\{robot_name\}_(?P<name>link_\d)">\s*<inertial>\s*'
            r'<origin rpy="(?P<rpy>[^"]+)" xyz="(?P<xyz>[^"]+)" />\s*'
            r'<mass value="(?P<mass>[^"]+)" />'
            r"\s*<inertia (?P<inertia>[^/]+)/>",
            text,
        )
    }
    joints = list(re.finditer(
        r'<joint name="\$\{robot_name\}_(?P<name>A\d)" type="revolute">\s*'
        r'<origin rpy="(?P<rpy>[^"]+)" xyz="(?P<xyz>[^"]+)" />.*?<axis xyz="(?P<axis>[^"]+)" />',
        text, re.S,
    ))  # fmt: skip
    flange = re.search(r'_joint_ee" type="fixed">.*?<origin xyz="([^"]+)"', text, re.S)
    assert len(joints) == 7 and len(links) == 8 and flange, "the xacro's layout changed"
    base = links["link_0"]
    lines = [
        "# KUKA LBR iiwa 14 R820 (`arm=iiwa14`): this project's own description, written by",
        "# studies/arms/write_iiwa14.py from lbr-stack/lbr_fri_ros2_stack's lbr_description",
        f"# (urdf/iiwa14/, Apache-2.0) at commit {COMMIT}; rated torques, payload and",
        "# reach from KUKA's datasheet. Every number's origin: README.md.",
        "name: iiwa14",
        "maker: KUKA",
        f"payload_kg: {PAYLOAD_KG}",
        f"reach_m: {REACH_M}",
        "# the LBR driver's joint names, under its robot name (lbr_A1 ...)",
        "joint_names: [A1, A2, A3, A4, A5, A6, A7]",
        "# a torque sensor in every joint; the FRI driver reports the measured torque",
        "torque_sensors: true",
        f"base: {{mass: {base['mass']}, com: [{', '.join(base['xyz'].split())}]}}   # link_0",
        "joints:",
    ]  # fmt: skip
    for k, joint in enumerate(joints):
        link = links[f"link_{k + 1}"]
        inertia = dict(re.findall(r'(i\w+)="([^"]+)"', link["inertia"]))
        lim = limits[joint["name"]]
        lines += [
            f"  - origin_xyz: {_numbers(joint['xyz'])}",
            f"    origin_rpy: {_numbers(joint['rpy'])}",
            f"    axis: {_numbers(joint['axis'])}",
            f"    limit: {{lower: {math.radians(lim['lower']):.6f}, upper: "
            f"{math.radians(lim['upper']):.6f}, velocity: {math.radians(lim['velocity']):.6f}, "
            f"effort: {RATED_TORQUE_NM[k]}}}",
            f"    mass: {float(link['mass'])}",
            f"    com: {_numbers(link['xyz'])}",
            "    inertia: {" + ", ".join(
                f"{c}: {float(inertia['i' + c])}" for c in ("xx", "yy", "zz", "xy", "xz", "yz")
            ) + "}",
        ]  # fmt: skip
    lines += ["# The flange in link 7 (the description's link_ee): where a payload is carried.",
              f"flange_xyz: {_numbers(flange[1])}"]  # fmt: skip
    atomic_write_text(OUT, "\n".join(lines) + "\n")
    print(f"-> {OUT}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
