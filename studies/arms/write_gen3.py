"""Write ``assets/gen3/arm.yaml`` from Kinova's description of the Gen3 7-DoF arm
(``Kinovarobotics/ros2_kortex``, ``kortex_description/arms/gen3/7dof/urdf/gen3_macro.xacro``,
BSD-3-Clause), with the vision module (its bracelet link's inertial) and the internal cabling:
joint frames, axes, link inertials, efforts and speeds; joints 1, 3, 5 and 7 turn without
limit (``continuous``); payload and reach from Kinova's datasheet.

    bash studies/arms/fetch_gen3.sh   # the xacro at the cited commit, into outputs/gen3/
    python studies/arms/write_gen3.py outputs/gen3
"""

from __future__ import annotations

import sys
from pathlib import Path

from urdf_chain import description_yaml, read_chain

from robohealth_mj.common.atomic import atomic_write_text

COMMIT = "1fdbef345954b326627dc3792981e18e2221450b"
CHOICES = {"vision": True, "use_external_cable": False, "sim_gazebo": False}
OUT = Path(__file__).resolve().parents[2] / "assets" / "gen3" / "arm.yaml"


def main(folder: Path) -> None:
    found = read_chain(folder / "gen3_macro.xacro", "base_link", CHOICES)
    chain, flange, base = found.joints, found.flange, found.base
    limits = [
        {k: float(j.limit[k]) for k in ("lower", "upper", "velocity", "effort") if k in j.limit}
        for j in chain
    ]
    header = [
        "Kinova Gen3 7-DoF with the vision module (`arm=gen3`): this project's own description,",
        "written by studies/arms/write_gen3.py from Kinovarobotics/ros2_kortex's",
        f"kortex_description (BSD-3-Clause) at commit {COMMIT};",
        "payload and reach from Kinova's datasheet. Every number's origin: README.md.",
    ]
    fields = {
        "name": "gen3", "maker": "Kinova", "payload_kg": "4.0", "reach_m": "0.902",
        "joint_names": f"[{', '.join(j.name for j in chain)}]   # the kortex driver's",
        "torque_sensors": "true   # one per actuator; the kortex driver reports it as effort",
    }  # fmt: skip
    atomic_write_text(OUT, description_yaml(header, fields, chain, limits, flange, base))
    print(f"-> {OUT}")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
