"""``python -m robohealth_mj.keystore keystore=PATH [enclave=/a/b grant=monitor ros2.arms=[...]]``.

An SROS2 keystore and enclaves for sites and tests without the ``ros2 security`` CLI
(robohealth_mj/ros2/keystore.py; the same layout, so either tool reads the other's):

    python -m robohealth_mj.keystore keystore=keys ros2.domain_id=0      # the CA, the governance
    python -m robohealth_mj.keystore keystore=keys enclave=/robohealth/monitor \\
        grant=monitor ros2.arms=[left,right] ros2.layout=ur_driver        # the monitor's enclave
    python -m robohealth_mj.keystore keystore=keys enclave=/dashboard \\
        grant=listener ros2.arms=[left,right]                             # a dashboard's
"""

from __future__ import annotations

from hydra.utils import instantiate
from omegaconf import DictConfig

from robohealth_mj.common.config import run_tool
from robohealth_mj.common.errors import InputError, one_line_errors


def main(argv: list[str] | None = None) -> None:
    run_tool("keystore", run, argv)


def run(cfg: DictConfig) -> None:
    with one_line_errors("keystore"):
        from robohealth_mj.ros2.keystore import (
            Keystore,
            create_enclave,
            create_keystore,
            open_keystore,
        )

        if not cfg.keystore:
            raise InputError("keystore=PATH is needed (or ROS_SECURITY_KEYSTORE)")
        domain = int(cfg.ros2.domain_id)
        if Keystore(cfg.keystore).is_valid():
            keystore = open_keystore(cfg.keystore, domain)
            print(f"keystore {keystore.root}: using its CA")
        else:
            keystore = create_keystore(cfg.keystore, domain)
            print(f"keystore {keystore.root}: made (CA, governance for domain {domain})")
        if cfg.enclave:
            grant = instantiate(cfg.grant)(cfg.ros2)
            folder = create_enclave(keystore, str(cfg.enclave), grant)
            print(f"enclave {cfg.enclave}: {folder} (publish {len(grant.publish)} topics, "
                  f"subscribe {len(grant.subscribe)})")  # fmt: skip


if __name__ == "__main__":
    main()
