"""A live ROS 2 participant over DDS (Eclipse Cyclone DDS's Python binding), without ROS 2.

ROS 2 talks DDS on the wire: a topic ``/a/b`` is the DDS topic ``rt/a/b``, a message type
``pkg/msg/Name`` the DDS type ``pkg::msg::dds_::Name_``, and the payload the same XCDR1 bytes that
``rosbags`` writes into bags. So this package builds the project's messages with the same
:class:`~robohealth_mj.bags.messages.MessageFactory` as the bag writer, over IDL classes instead
of ``rosbags`` ones, and reads them back with the bag reader's assembly. The binding is optional
(``pip install .[ros2]``); :func:`require_dds` says so in one line where it is missing.
"""

from __future__ import annotations

from robohealth_mj.common.errors import InputError

# The sensing profile (conf/sensing/) each live layout's topics deliver: a model may read those
# channels or fewer (the monitor refuses one that reads more, in one line).
LAYOUT_SENSING = {
    "per_sensor": "full",  # the bag's topics: every channel
    "aggregated": "full",  # the snapshot in one array
    "joints": "stock",  # a stock arm's joint state and tracking error (this project's topics)
    "ur_driver": "ur_driver",  # the UR driver's own: no torque residual
}


def layout_sensing(layout: str) -> str:
    """The sensing profile ``ros2.layout``'s topics deliver; one line for an unknown layout."""
    if layout not in LAYOUT_SENSING:
        raise InputError(f"ros2.layout must be one of {list(LAYOUT_SENSING)}, got {layout!r}")
    return LAYOUT_SENSING[layout]


def require_dds() -> None:
    """Import the DDS binding or fail with one line saying how to install it."""
    try:
        import cyclonedds  # noqa: F401
    except ImportError:
        raise InputError(
            "the ROS 2 bridge needs the cyclonedds package: pip install '.[ros2]'"
        ) from None
