"""``python -m robohealth_mj``: the commands, one line each; each runs as
``python -m robohealth_mj.<name>``."""

from __future__ import annotations

import sys

# (command, extra it needs beyond the base install, what it does); a test keeps this list equal
# to the entry points at the package root.
COMMANDS = (
    ("record", "sim", "record one labelled session on the physics"),
    (
        "corpus",
        "sim",
        "record every dataset role of a corpus, resumable (corpus=quick|standard|lives)",
    ),
    ("dataset", "", "summarise, gate and merge recordings"),
    ("effects", "sim", "fault effect sizes on every channel"),
    ("train", "train", "train one variant and evaluate it; -m for multi-seed campaigns"),
    ("evaluate", "train", "score a checkpoint on whole recordings"),
    ("report", "train", "a campaign directory into tables and figures"),
    ("export", "train", "a checkpoint to ONNX for the torch-free runtime"),
    ("commission", "train", "fit a model to a new arm from minutes of its healthy running"),
    ("tune_alarms", "", "choose alarm settings on a selection recording"),
    ("monitor", "", "diagnose a simulated, replayed or live (ROS 2) stream"),
    ("robot", "monitor", "simulated or replayed arms publishing on a ROS 2 bus"),
    ("keystore", "monitor", "an SROS2 keystore and enclaves, without ROS installed"),
    ("render", "sim", "a fault episode rendered headless to GIF/MP4"),
    ("bag", "", "recordings to and from ROS 2 bags"),
    ("ingest", "", "a controller log (UR RTDE, voraus-AD, any mapped table) to a recording"),
    ("identify", "sim", "a real arm's twin from its healthy controller logs"),
    ("bench", "", "throughput benchmarks: sim, models, train, infer, streams, soak, ros2, contact"),
)


def main() -> int:
    print("robohealth_mj: mechanical health monitoring of robot arms.\n")
    print("Run one as `python -m robohealth_mj.<command>` (`--help` on each):\n")
    for name, extra, what in COMMANDS:
        needs = f"  [{extra}]" if extra else ""
        print(f"  {name:<12} {what}{needs}")
    print("\n[extra]: pip install 'robohealth_mj[extra]' (the base install runs the rest)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
