"""What each participant of this project may do on a secured graph, from the same ``ros2.*``
settings the monitor and the simulated arms run with: the topics each one opens, and no other.

Each grant is built through ``conf/grant/<name>.yaml`` by ``python -m robohealth_mj.keystore``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from robohealth_mj.common.errors import InputError
from robohealth_mj.ros2.keystore import Grant


def _arm_topics(ros2: Any) -> tuple[list[str], list[str]]:
    """The configured arms' topics in the configured layout (as the monitor and robot open
    them), and where their diagnoses are published."""
    from robohealth_mj.ros2.live import arm_names, layout_options
    from robohealth_mj.ros2.node import arm_kinds, arm_topics

    options = layout_options(ros2)
    samples, diagnoses = [], []
    for arm in arm_names(ros2):
        names = arm_topics(arm, None, options["namespace"])
        samples += arm_kinds(names, arm, options["layout"], options["driver"], options["namespace"])
        diagnoses.append(names.health_diagnosis)
    if not diagnoses:
        raise InputError("ros2.arms: no arms to grant (ros2.arms=[...] or ros2.count=N)")
    return list(dict.fromkeys(samples)), list(dict.fromkeys(diagnoses))


def monitor_grant(ros2: Any) -> Grant:
    """The monitor: read every arm's topics; write ``/diagnostics`` and each arm's
    ``health_diagnosis``; in a monitor group (``ros2.group.enable``) also write and read the
    group's heartbeats; nothing else."""
    from robohealth_mj.ros2.group import GROUP_TOPIC
    from robohealth_mj.ros2.node import DIAGNOSTICS_TOPIC

    samples, diagnoses = _arm_topics(ros2)
    group = (GROUP_TOPIC,) if (ros2.get("group") or {}).get("enable") else ()
    return Grant(publish=(DIAGNOSTICS_TOPIC, *diagnoses, *group), subscribe=(*samples, *group))


def robot_grant(ros2: Any) -> Grant:
    """A robot (``python -m robohealth_mj.robot``, or a driver's stand-in): write its arms'
    topics; read nothing."""
    samples, _ = _arm_topics(ros2)
    return Grant(publish=tuple(samples))


def listener_grant(ros2: Any) -> Grant:
    """A dashboard or recorder: read ``/diagnostics`` and each arm's ``health_diagnosis``."""
    from robohealth_mj.ros2.node import DIAGNOSTICS_TOPIC

    _, diagnoses = _arm_topics(ros2)
    return Grant(subscribe=(DIAGNOSTICS_TOPIC, *diagnoses))


def everything_grant(ros2: Any = None) -> Grant:
    """sros2's default for a new enclave: every topic, both ways."""
    return Grant.everything()


def topics_grant(publish: Sequence[str] = (), subscribe: Sequence[str] = ()) -> Any:
    """The topics named (ROS names, ``*`` any characters), as a grant builder."""

    def build(ros2: Any = None) -> Grant:
        names = [*publish, *subscribe]
        if not names:
            raise InputError("grant=topics needs grant.publish=[...] or grant.subscribe=[...]")
        for name in names:
            if not str(name).startswith("/"):
                raise InputError(
                    f"grant: topic {name!r} must be a ROS name such as /arm1/joint_states"
                )
        return Grant(publish=tuple(map(str, publish)), subscribe=tuple(map(str, subscribe)))

    return build
