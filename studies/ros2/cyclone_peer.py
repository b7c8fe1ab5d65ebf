"""The project's own DDS participant (``ros2/bus.py``, Cyclone) on the other end of
``fastdds_peer.py``: reads or writes ``/arm1/joint_states`` with a given type-information setting
and prints how many messages went through.

    python cyclone_peer.py read true 7      # ignore_type_information=true, listen 7 s
    python cyclone_peer.py write false 60   # 60 JointStates at 20 Hz
"""

from __future__ import annotations

import sys
import time

from robohealth_mj.bags.messages import MessageFactory
from robohealth_mj.ros2.bus import Bus, BusConfig
from robohealth_mj.ros2.idl import TYPES, IdlStore

TOPIC = "/arm1/joint_states"
JOINT_STATE = TYPES["sensor_msgs/msg/JointState"]


def main() -> None:
    mode, ignore, amount = sys.argv[1], sys.argv[2] == "true", float(sys.argv[3])
    bus = Bus(BusConfig(domain_id=0, interface="127.0.0.1", ignore_type_information=ignore))
    if mode == "read":
        reader = bus.reader(TOPIC, JOINT_STATE)
        got, started = 0, time.monotonic()
        while time.monotonic() - started < amount:
            got += sum(isinstance(m, JOINT_STATE) for m in reader.take(N=100))
            time.sleep(0.01)
        print(f"cyclone reader (ignore_type_information={ignore}): {got} received", flush=True)
    else:
        writer, factory = bus.writer(TOPIC, JOINT_STATE), MessageFactory(IdlStore())
        time.sleep(2.5)  # discovery
        for k in range(int(amount)):
            writer.write(JOINT_STATE(header=factory.header(k * 0.05), name=list("abcdef"),
                                     position=[0.0] * 6, velocity=[0.0] * 6,
                                     effort=[0.0] * 6))  # fmt: skip
            time.sleep(0.05)
        time.sleep(1.5)
        print(f"cyclone writer (ignore_type_information={ignore}): {int(amount)} written")
    bus.close()


if __name__ == "__main__":
    main()
