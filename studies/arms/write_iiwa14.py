"""Write ``assets/iiwa14/arm.yaml`` from the community description of the KUKA LBR iiwa 14 R820
(``lbr-stack/lbr_fri_ros2_stack``, ``lbr_description/urdf/iiwa14/``, Apache-2.0): its joint
frames, axes and link inertials from the xacro, the position and speed limits from its
``joint_limits.yaml`` (degrees), the rated torques from KUKA's datasheet (the description's
efforts are a placeholder 200 N m on every joint).

    bash studies/arms/fetch_iiwa14.sh   # the two files at the cited commit, into outputs/iiwa14/
    python studies/arms/write_iiwa14.py outputs/iiwa14
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import yaml
from urdf_chain import description_yaml, read_chain

from robohealth_mj.common.atomic import atomic_write_text

COMMIT = "218d723f817c61314988833611effddc5333ca6c"
# KUKA's LBR iiwa 14 R820 datasheet: maximum torque per axis (N m), rated payload, reach.
RATED_TORQUE_NM = [320.0, 320.0, 176.0, 176.0, 110.0, 40.0, 40.0]
OUT = Path(__file__).resolve().parents[2] / "assets" / "iiwa14" / "arm.yaml"


def main(folder: Path) -> None:
    found = read_chain(folder / "iiwa14_description.xacro", "link_0")
    chain, flange, base = found.joints, found.flange, found.base
    degrees = yaml.safe_load((folder / "joint_limits.yaml").read_text())
    limits = [
        {"lower": round(math.radians(d["lower"]), 6), "upper": round(math.radians(d["upper"]), 6),
         "velocity": round(math.radians(d["velocity"]), 6), "effort": torque}
        for d, torque in zip((degrees[j.name] for j in chain), RATED_TORQUE_NM, strict=True)
    ]  # fmt: skip
    header = [
        "KUKA LBR iiwa 14 R820 (`arm=iiwa14`): this project's own description, written by",
        "studies/arms/write_iiwa14.py from lbr-stack/lbr_fri_ros2_stack's lbr_description",
        f"(urdf/iiwa14/, Apache-2.0) at commit {COMMIT};",
        "rated torques, payload and reach from KUKA's datasheet. Every number's origin: README.md.",
    ]
    fields = {
        "name": "iiwa14", "maker": "KUKA", "payload_kg": "14.0", "reach_m": "0.82",
        "joint_names": f"[{', '.join(j.name for j in chain)}]   # the LBR driver's (lbr_A1 ...)",
        "torque_sensors": "true   # one per joint; the FRI driver reports the measured torque",
    }  # fmt: skip
    atomic_write_text(OUT, description_yaml(header, fields, chain, limits, flange, base))
    print(f"-> {OUT}")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
