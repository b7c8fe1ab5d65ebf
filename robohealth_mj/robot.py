"""``python -m robohealth_mj.robot``: simulated arms publishing on the ROS 2 bus, as a driver would.

    python -m robohealth_mj.robot ros2.count=4 duration_s=120              # 4 simulated arms
    python -m robohealth_mj.robot source=replay file=graphs.jsonl speed=0 ros2.arms=[cell1]

Each arm publishes the bag topic layout under its namespace (``/<arm>/joint_states`` …) with
``/<arm>/fault_state`` as ground truth, so ``monitor source=ros2`` and its on-line evaluation run
with no robot at all. Bus settings: ``conf/ros2/default.yaml`` (``ros2.domain_id``,
``ros2.interface`` …).
"""

from __future__ import annotations

from pathlib import Path

from omegaconf import DictConfig

from robohealth_mj.bags import is_bag
from robohealth_mj.common.config import run_tool
from robohealth_mj.common.errors import InputError, one_line_errors


def main(argv: list[str] | None = None) -> int | None:
    return run_tool("robot", run, argv)


def run(cfg: DictConfig) -> int:
    with one_line_errors("robot"):
        from robohealth_mj.ros2.live import run_robot
        from robohealth_mj.runtime.sources import replay_stream, sim_stream

        if cfg.source == "sim":
            stream = ((t, s) for t, s, _ in sim_stream(list(cfg.sim_overrides), cfg.duration_s))
        elif cfg.source == "replay":
            if not cfg.file or not (Path(cfg.file).is_file() or is_bag(cfg.file)):
                raise FileNotFoundError(f"source=replay needs file=PATH (got {cfg.file})")
            stream = ((t, s) for t, s, _ in replay_stream(cfg.file) if not isinstance(s, str))
        else:
            raise InputError(f"source must be sim or replay, got {cfg.source!r}")
        ticks = run_robot(cfg, stream)
        print(f"published {ticks} ticks on each of the arms", flush=True)
        return ticks


if __name__ == "__main__":
    main()
