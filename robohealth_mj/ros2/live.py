"""Long-running loops on the bus: the monitor (``monitor source=ros2``: :func:`monitor_arms`,
live arms pushing into the monitor's session) and simulated arms
(``python -m robohealth_mj.robot``). Both stop cleanly on Ctrl-C or SIGTERM: the last
``/diagnostics`` is published and the participants are closed."""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from omegaconf import DictConfig

from robohealth_mj.common.errors import InputError
from robohealth_mj.data.sensing import load_profile
from robohealth_mj.ros2 import require_dds
from robohealth_mj.schema import GraphSample


def bus_config(cfg: DictConfig) -> Any:
    """The participant ``ros2.*`` describes, its SROS2 enclave resolved (one line where an
    enforced one cannot be used)."""
    from robohealth_mj.ros2.bus import BusConfig
    from robohealth_mj.ros2.security import resolve_security

    return BusConfig(
        domain_id=int(cfg.domain_id),
        interface=cfg.interface,
        ignore_type_information=bool(cfg.ignore_type_information),
        reliable_subscriptions=bool(cfg.get("reliable_subscriptions", False)),
        depth=int(cfg.get("depth", 10)),
        security=resolve_security(cfg.get("security"), int(cfg.domain_id)),
    )


def layout_options(
    cfg: DictConfig, tracking: bool = True, arm: str | None = None
) -> dict[str, Any]:
    """The arm-side settings of ``conf/ros2/default.yaml`` as keyword arguments of ``MonitorNode``
    and ``ArmPublisher``: layout, namespace, joint names and, for ``ur_driver``, the driver's side
    (``tracking``: the model reads ``pos_error``, so the controller state is awaited). ``arm``:
    the arm the model reads, whose driver's joint names ``joint_names=auto`` takes on the
    ``ur_driver`` layout (any ros2_control driver's: a UR's, an FR3's ...)."""
    from robohealth_mj.arms.description import load_arm
    from robohealth_mj.ros2.driver import DriverConfig

    layout = str(cfg.layout)
    names = cfg.get("joint_names", "auto")
    if names == "auto" and layout == "ur_driver" and arm is not None:
        names = list(load_arm(arm).joint_names)
    elif names == "auto":
        names = "ur_driver" if layout == "ur_driver" else "schema"
    scale = cfg.get("effort_scale")
    driver = DriverConfig(
        controller_state=str(cfg.get("controller_state", DriverConfig.controller_state)),
        distro=str(cfg.get("distro", DriverConfig.distro)),
        tracking=tracking,
        tick_hz=float(cfg.get("tick_hz", DriverConfig.tick_hz)),
        timeout_s=float(cfg.get("controller_timeout_s", DriverConfig.timeout_s)),
        effort_scale=None if scale is None else tuple(float(v) for v in scale),
    )
    return {"layout": layout, "namespace": str(cfg.get("namespace", "/{arm}")),
            "joint_names": names, "tf_prefix": str(cfg.get("tf_prefix") or ""),
            "driver": driver}  # fmt: skip


def model_arm(runtime: Any) -> str | None:
    """The arm the runtime's model reads (None without a model)."""
    fleet = getattr(runtime, "fleet", runtime)
    return fleet.arm if getattr(fleet, "engine", None) is not None else None


@contextmanager
def stop_on_signals() -> Iterator[threading.Event]:
    """An event set by SIGINT or SIGTERM while the block runs (handlers restored after)."""
    stop = threading.Event()
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    for s in previous:
        signal.signal(s, lambda *_: stop.set())
    try:
        yield stop
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


def arm_names(cfg: DictConfig) -> list[str]:
    """The configured arms (a list, or ``count`` names from ``prefix``), this process's share."""
    from robohealth_mj.ros2.node import in_partition

    arms = list(cfg.arms) if cfg.arms else [f"{cfg.prefix}{k + 1}" for k in range(int(cfg.count))]
    return [a for a in arms if in_partition(a, cfg.partition)]


def run_monitor(
    cfg: DictConfig,
    runtime: Any,
    duration_s: float | None,
    on_diagnosis: Callable[[str, GraphSample, Any], None] | None = None,
    tracking: bool = True,
) -> dict[str, Any]:
    """Diagnose the configured arms until the duration ends or a signal comes; each diagnosis
    also goes to ``on_diagnosis(arm, sample, diagnosis)`` (the on-line evaluation);
    ``tracking``: the model reads the tracking error (``ur_driver``: await the controller)."""
    require_dds()
    from robohealth_mj.ros2.bus import Bus
    from robohealth_mj.ros2.group import MonitorGroup, group_config
    from robohealth_mj.ros2.node import MonitorNode, poll_paced

    grouped = group_config(cfg.get("group"))
    if grouped is not None and cfg.partition:
        raise InputError("ros2.group.enable=true shares the arms itself: drop ros2.partition "
                         f"({cfg.partition!r}), the static split")  # fmt: skip
    arms = arm_names(cfg)
    if not arms:
        raise ValueError("ros2: no arms in this process's partition")
    config = bus_config(cfg)
    with Bus(config) as bus:  # deleted at once on a refusal, not left to the exit
        group = MonitorGroup(bus, grouped, arms) if grouped is not None else None
        watched = group.discover() if group is not None else arms
        node = MonitorNode(bus, runtime, watched, require_truth=bool(cfg.require_truth),
                           stale_s=float(cfg.stale_s), on_diagnosis=on_diagnosis,
                           health_diagnosis_hz=float(cfg.get("health_diagnosis_hz", 20.0)),
                           tick_hz=float(cfg.get("tick_hz", 20.0)),
                           diagnose_wait_s=float(cfg.get("diagnose_wait_s", 0.02)),
                           late_ticks=int(cfg.get("late_ticks", 10)),
                           member=grouped.member if grouped is not None else None,
                           **layout_options(cfg, tracking, model_arm(runtime)))  # fmt: skip
        started = time.monotonic()
        last_report = started
        secured = f", secured as {config.security.enclave}" if config.security else ""
        print(f"ros2 monitor: {len(watched)} arms on domain {cfg.domain_id}{secured} "
              f"({', '.join(watched[:5])}{' …' if len(watched) > 5 else ''}); Ctrl-C to stop",
              flush=True)  # fmt: skip
        if group is not None:
            _say_group(group, node)
        with stop_on_signals() as stop:
            try:
                while not stop.is_set():
                    now = time.monotonic()
                    if duration_s and now - started >= duration_s:
                        break
                    poll_paced(node, float(cfg.poll_s))  # what arrived in a period, in one go
                    if group is not None and (wanted := group.update()) != list(node.arms):
                        node.set_arms(wanted)  # a member came or went
                        _say_group(group, node)
                    if now - last_report >= float(cfg.diagnostics_period_s):
                        node.publish_diagnostics(time.time())
                        for arm, problem in node.reported:  # as it happens, not only at the end
                            print(f"{arm}: {problem}", flush=True)
                        last_report = now
            finally:
                if group is not None:
                    group.leave()  # the others take this monitor's arms now, not after a timeout
                node.publish_diagnostics(time.time())  # the last word on every arm
    return {
        arm: {
            "samples": s.samples,
            "problems": s.problems,
            "late": s.late,
            "duplicates": s.duplicates,
            "last_problem": s.last_problem,
        }
        for arm, s in {**node.released, **node.arms}.items()
    }


def _say_group(group: Any, node: Any) -> None:
    members = group.members()
    print(f"ros2 group: {group.me} watches {len(node.arms)} of {len(group.arms)} arms; members "
          f"{', '.join(members)}", flush=True)  # fmt: skip


def wait_for_subscribers(writers: list[Any], timeout_s: float) -> bool:
    """Until every writer has matched a reader (on a secured graph: its keys exchanged), at
    most ``timeout_s``: what is written before a reader matches never reaches it. Whether all
    did."""
    from robohealth_mj.ros2.bus import Bus

    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if all(Bus.matched_readers(w) for w in writers):
            return True
        time.sleep(0.05)
    return False


def run_robot(cfg: DictConfig, stream: Iterator[tuple[float, GraphSample]]) -> int:
    """Publish each sample of ``stream`` on every configured arm, paced at ``speed`` x real
    time (0: as fast as possible); returns the ticks published."""
    require_dds()
    from robohealth_mj.ros2.bus import Bus
    from robohealth_mj.ros2.node import ArmPublisher

    with Bus(bus_config(cfg.ros2)) as bus:  # deleted at once on a refusal, not left to the exit
        arms = [ArmPublisher(bus, arm, **layout_options(cfg.ros2)) for arm in arm_names(cfg.ros2)]
        wait_for_subscribers([w for arm in arms for w in arm.writers.values()],
                             float(cfg.discovery_s))  # fmt: skip
        ticks, started, t0 = 0, time.perf_counter(), None
        with stop_on_signals() as stop:
            try:
                for t, sample in stream:
                    if stop.is_set():
                        break
                    t0 = t if t0 is None else t0
                    if cfg.speed:
                        delay = (t - t0) / cfg.speed - (time.perf_counter() - started)
                        if delay > 0:
                            time.sleep(delay)
                    for arm in arms:
                        arm.publish(sample)
                    ticks += 1
            finally:
                time.sleep(0.2)  # reliable writers flush before the participant goes
    return ticks


def monitor_arms(cfg: DictConfig, runtime: Any, policy: Any, evidence: Any) -> dict | None:
    """``source=ros2``: live arms on the bus pushing into the monitor's session (the one a
    replay is pulled through): with ``evaluate``, one on-line evaluation per arm against its
    ``fault_state``; with ``health.state_dir``, each arm's wear."""
    from robohealth_mj.ros2 import layout_sensing
    from robohealth_mj.runtime.monitor import MonitorSession, refuse_lacking_data

    if runtime.fleet.engine is not None:  # a model reading more than the layout carries
        layout = cfg.ros2.layout
        refuse_lacking_data(runtime.fleet.sensing, layout_sensing(layout), f"ros2.layout={layout}")
    with MonitorSession(cfg, runtime, policy, evidence, print_changes=False) as session:

        def diagnosed(arm: str, sample: GraphSample, d: Any) -> None:
            session.diagnosed(arm, sample.t, sample, sample.fault, d)

        reads_tracking = "pos_error" in load_profile(runtime.fleet.sensing).joint_channels
        counts = run_monitor(cfg.ros2, runtime, cfg.duration_s or None, diagnosed, reads_tracking)
    for arm, c in counts.items():
        last = f" (last: {c['last_problem']})" if c["last_problem"] else ""
        print(f"{arm}: {c['samples']} samples diagnosed, {c['problems']} bad inputs, "
              f"{c['late']} late, {c['duplicates']} duplicate messages{last}")  # fmt: skip
    return session.finish()
