"""A dashboard on the bus for the security tests (``test_security.py``): it subscribes to
``/diagnostics`` and each arm's ``health_diagnosis`` as the participant the environment makes it
(``ROS_SECURITY_*``: secured, or open), and writes how many messages of each it heard once the
expected count came, time ran out or SIGTERM came. Run by whichever binding the test asks for.

    python diagnosis_listener.py DOMAIN SECONDS EXPECTED OUT.json ARM [ARM ...]
"""

from __future__ import annotations

import json
import signal
import sys
import time
from pathlib import Path

from robohealth_mj.ros2.bus import Bus, BusConfig
from robohealth_mj.ros2.idl import DiagnosticArray
from robohealth_mj.ros2.security import resolve_security


def main() -> None:
    domain, seconds, expected = int(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
    out, arms = Path(sys.argv[4]), sys.argv[5:]
    security = resolve_security({"enclave": "/dashboard"}, domain)
    bus = Bus(BusConfig(domain_id=domain, interface="127.0.0.1", reliable_subscriptions=True,
                        depth=1000, security=security))  # fmt: skip
    readers = {"/diagnostics": bus.reader("/diagnostics", DiagnosticArray)}
    for arm in arms:
        readers[f"/{arm}/health_diagnosis"] = bus.reader(
            f"/{arm}/health_diagnosis", DiagnosticArray
        )
    heard = dict.fromkeys(readers, 0)
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(True))
    print("listening", flush=True)
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and not stop:
        for topic, reader in readers.items():
            heard[topic] += len(reader.take(N=1000))
        if all(heard[f"/{arm}/health_diagnosis"] >= expected for arm in arms):
            break
        time.sleep(0.02)
    out.write_text(json.dumps({"secured": security is not None, "heard": heard}))
    bus.close()


if __name__ == "__main__":
    main()
