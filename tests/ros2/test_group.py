"""Monitors that cover for each other (``ros2.group``): the rendezvous split, membership by
heartbeat on loopback, arms moving in and out of a running monitor, and three monitor processes
of the command line under kill and restart."""

from __future__ import annotations

import itertools
import os
import threading
import time

import pytest
from omegaconf import OmegaConf

pytest.importorskip("cyclonedds", reason="the ROS 2 bridge needs cyclonedds: pip install '.[ros2]'")

from robohealth_mj.common.errors import InputError
from robohealth_mj.data.read import read_samples
from robohealth_mj.ros2.bus import Bus, BusConfig
from robohealth_mj.ros2.group import GroupConfig, MonitorGroup, group_config, owner, share
from robohealth_mj.ros2.node import ArmPublisher, MonitorNode
from robohealth_mj.runtime.runtime import ModelRuntime

_DOMAINS = itertools.count(216 + os.getpid() % 8)  # apart from the other DDS tests' ids
ARMS = [f"arm{k}" for k in range(1, 61)]


def _bus(domain: int) -> Bus:
    return Bus(BusConfig(domain_id=domain, interface="127.0.0.1"))


def test_every_arm_has_one_owner_whatever_order_the_members_are_listed_in():
    members = ["monitor0", "monitor1", "monitor2"]
    owners = {a: owner(a, members) for a in ARMS}
    for order in itertools.permutations(members):
        assert {a: owner(a, order) for a in ARMS} == owners
    shares = [share(ARMS, members, m) for m in members]
    assert sorted(a for s in shares for a in s) == sorted(ARMS) and all(shares)


def test_a_member_leaving_moves_only_its_arms_and_one_joining_takes_only_its_own():
    members = ["monitor0", "monitor1", "monitor2"]
    before = {a: owner(a, members) for a in ARMS}
    after = {a: owner(a, members[1:]) for a in ARMS}
    assert {a for a in ARMS if before[a] != after[a]} == set(share(ARMS, members, "monitor0"))
    joined = {a: owner(a, [*members, "monitor3"]) for a in ARMS}
    moved = {a for a in ARMS if joined[a] != before[a]}
    assert moved and all(joined[a] == "monitor3" for a in moved)


def test_the_group_s_settings_are_checked_in_one_line():
    assert group_config(OmegaConf.create({"enable": False})) is None
    made = group_config(OmegaConf.create({"enable": True, "member": "m1"}))
    assert made == GroupConfig(member="m1")
    with pytest.raises(InputError, match=r"ros2.group.timeout_s: 0.3 must exceed two heartbeats"):
        group_config(OmegaConf.create({"enable": True, "timeout_s": 0.3, "heartbeat_s": 0.2}))
    with pytest.raises(InputError, match=r"ros2.group.handover_s: 'soon' is not a positive"):
        group_config(OmegaConf.create({"enable": True, "handover_s": "soon"}))


def _until(condition, timeout_s: float = 10.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline and not condition():
        time.sleep(0.02)


class _Alive:
    """A member heartbeating from a thread until it is stopped (silently, as when killed)."""

    def __init__(self, group: MonitorGroup) -> None:
        self.group, self.stop = group, threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self.stop.is_set():
            self.group.update()
            time.sleep(0.02)

    def kill(self) -> None:
        self.stop.set()
        self.thread.join()


def test_members_find_each_other_share_the_arms_and_take_over_from_a_silent_one():
    """Each member takes its share after discovery; when one stops heartbeating, the other
    takes every arm after the timeout; a joiner diagnoses its share at once while the owner
    keeps it through the handover; one that leaves says so and its arms move at once."""
    domain = next(_DOMAINS)
    config = {"heartbeat_s": 0.05, "timeout_s": 0.4, "handover_s": 1.0}
    buses = [_bus(domain) for _ in range(3)]
    a = MonitorGroup(buses[0], GroupConfig("a", **config), ARMS)
    b = MonitorGroup(buses[1], GroupConfig("b", **config), ARMS)
    time.sleep(0.5)  # the heartbeat topic's readers and writers match on loopback
    alive_b = _Alive(b)
    assert a.discover() == share(ARMS, ["a", "b"], "a") and a.members() == ["a", "b"]

    alive_b.kill()
    silent_since = time.monotonic()
    c = MonitorGroup(buses[2], GroupConfig("c", **config), ARMS)  # matches meanwhile
    _until(lambda: a.update() == ARMS)
    assert a.update() == ARMS and 0.2 < time.monotonic() - silent_since < 2.0

    alive_a = _Alive(a)  # a goes on heartbeating while c discovers
    c_share = c.discover()
    alive_a.kill()
    assert c_share == share(ARMS, ["a", "c"], "c")  # c diagnoses its share at once ...
    assert a.update() == ARMS  # ... while a keeps it through the handover, counted from c's
    active = time.monotonic()  # first update (its readers made), not from its first beat
    _until(lambda: (c.update(), a.update())[1] == share(ARMS, ["a", "c"], "a"))
    assert a.update() == share(ARMS, ["a", "c"], "a") and time.monotonic() - active >= 1.0

    # c restarted faster than the timeout: its arms come back to a while it says it is joining
    alive_c = _Alive(c)
    again = MonitorGroup(buses[2], GroupConfig("c", **{**config, "timeout_s": 3.0}), ARMS)
    joining = threading.Thread(target=again.discover, daemon=True)
    joining.start()
    alive_c.kill()
    _until(lambda: a.update() == ARMS, timeout_s=2.5)
    assert a.update() == ARMS and joining.is_alive()  # not a's timeout: "c" beats throughout
    joining.join()
    c = again  # active now: a lets its share go after the handover again
    _until(lambda: (c.update(), a.update())[1] == share(ARMS, ["a", "c"], "a"))
    assert a.update() == share(ARMS, ["a", "c"], "a")

    c.leave()
    _until(lambda: a.update() == ARMS, timeout_s=0.3)  # at once, not after the timeout
    assert a.update() == ARMS
    for bus in buses:
        bus.close()


def test_arms_moved_out_and_back_in_lose_their_readers_then_start_a_fresh_window(deployed):
    domain = next(_DOMAINS)
    robot, monitor = _bus(domain), _bus(domain)
    samples = list(itertools.islice(read_samples(deployed["heldout"]), 30))
    runtime = ModelRuntime(deployed["structural_onnx"])
    node = MonitorNode(monitor, runtime, ["arm1", "arm2"], keep_diagnoses=True,
                       diagnose_wait_s=0.0, member="m0")  # fmt: skip
    pubs = {a: ArmPublisher(robot, a) for a in ("arm1", "arm2")}
    time.sleep(0.5)  # discovery on loopback

    def publish(batch, arms) -> None:
        for s in batch:
            for arm in arms:
                pubs[arm].publish(s)
            node.poll()
            time.sleep(0.01)

    publish(samples[:10], ["arm1", "arm2"])
    _until(lambda: (node.poll(), node.arms["arm2"].samples)[1] >= 10)
    node.set_arms(["arm1"])
    assert list(node.arms) == ["arm1"] and "arm2" not in runtime.streams
    publish(samples[10:20], ["arm1", "arm2"])  # arm2's are no longer read
    _until(lambda: (node.poll(), node.arms["arm1"].samples)[1] >= 20)
    assert node.released["arm2"].samples == 10
    status = {s.hardware_id: s for s in node.publish_diagnostics(0.0).status}
    assert set(status) == {"arm1"}
    assert {v.key: v.value for v in status["arm1"].values}["monitor"] == "m0"

    node.set_arms(["arm1", "arm2"])
    time.sleep(0.5)  # the new readers match
    publish(samples[20:30], ["arm1", "arm2"])
    _until(lambda: (node.poll(), node.arms["arm2"].samples)[1] >= 20)
    assert node.arms["arm2"].samples == 20  # counts carried over; none of 10..19 taken late
    again = node.arms["arm2"].diagnoses[-10:]
    assert again[0].reason and "warming" in again[0].reason  # its window starts afresh
    for bus in (robot, monitor):
        bus.close()


def test_the_failover_bench_counts_a_hole_as_lost_but_not_a_lagging_monitor_s_ticks():
    """Lost ticks are counted in stamps: a killed monitor's ticks still in flight and ticks on
    their way to the listener are no loss; a tick missing between two diagnoses is."""
    from robohealth_mj.benchmarks.failover import Arrivals

    arrivals = Arrivals()
    for stamp in range(20):  # arm1: every tick, on time, from writer 1
        arrivals.rows["arm1"].append((stamp * 0.05, stamp, 1, True))
    # arm2's monitor (writer 2) lags 0.5 s and dies at 0.6 s having diagnosed ticks 0 and 1;
    # writer 3 takes the arm from tick 14, and its newest ticks have not arrived yet
    arrivals.rows["arm2"] += [(0.5 + stamp * 0.05, stamp, 2, True) for stamp in range(2)]
    arrivals.rows["arm2"] += [(0.1 + stamp * 0.05, stamp, 3, False) for stamp in range(14, 18)]
    gap = arrivals.gap("arm2", 0.6, victim={2})
    assert gap == (1, 14) and arrivals.lost({"arm2": [gap]}) == 0
    del arrivals.rows["arm2"][3]  # the taker misses tick 15
    assert arrivals.lost({"arm2": [gap]}) == 1
    assert arrivals.lost({}) == 12 + 1  # ticks 2..13 without the gap


def test_three_monitor_processes_cover_for_one_killed_and_take_it_back_on_restart(deployed):
    """The command line end to end (the benchmark's harness, one cycle): SIGKILL one of three
    monitors sharing 12 arms; the others diagnose its arms again, no tick is diagnosed twice once
    the change settled or lost outside the gap, and the restarted monitor gets its arms back."""
    from robohealth_mj.benchmarks.failover import failover

    samples = list(itertools.islice(read_samples(deployed["heldout"]), 100))
    rows = failover(str(deployed["structural_onnx"]), samples, monitors=3, arms=12, cycles=1,
                    domain=next(_DOMAINS), handover_s=1.0)  # fmt: skip
    (row,) = rows
    assert row["arms"] >= 1
    assert row["recovered_max_s"] < 5.0, row  # 2 s on an idle machine (bench ros2 --kill 1)
    assert row["twice_after_3s"] == 0 and row["lost"] == 0, row
    assert row["shares_restored"], row


@pytest.mark.parametrize(
    "override, needle",
    [
        (
            "ros2.partition=0/2",
            "ros2.group.enable=true shares the arms itself: drop ros2.partition",
        ),
        ("ros2.group.timeout_s=0.1", "ros2.group.timeout_s: 0.1 must exceed two heartbeats"),
    ],
)
def test_a_group_setting_that_cannot_work_is_one_line_and_exit_status_2(deployed, override, needle):
    import subprocess
    import sys

    args = [sys.executable, "-m", "robohealth_mj.monitor", f"model={deployed['structural_onnx']}",
            "source=ros2", "duration_s=1", f"ros2.domain_id={next(_DOMAINS)}",
            "ros2.interface=127.0.0.1", "ros2.group.enable=true", override]  # fmt: skip
    proc = subprocess.run(args, capture_output=True, text=True, timeout=120)
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert len(lines) == 1 and needle in lines[0], proc.stderr


def test_a_grouped_monitor_s_grant_adds_the_group_topic_both_ways():
    from robohealth_mj.common.config import compose_config
    from robohealth_mj.ros2.grants import monitor_grant
    from robohealth_mj.ros2.group import GROUP_TOPIC

    alone = monitor_grant(compose_config("keystore", ["ros2.count=2"]).ros2)
    grouped = monitor_grant(
        compose_config("keystore", ["ros2.count=2", "ros2.group.enable=true"]).ros2
    )
    assert GROUP_TOPIC not in alone.publish + alone.subscribe
    assert GROUP_TOPIC in grouped.publish and GROUP_TOPIC in grouped.subscribe
    assert set(grouped.publish) - set(alone.publish) == {GROUP_TOPIC}


class _Queued:
    """A heartbeat reader whose beats wait until taken, as on the bus: (name, sent ns) pairs."""

    def __init__(self) -> None:
        self.beats: list[tuple[str, int]] = []

    def take(self, N: int) -> list:  # N: as the binding names it
        from types import SimpleNamespace

        out, self.beats = self.beats[:N], self.beats[N:]
        return [SimpleNamespace(name=n, message="active",
                                sample_info=SimpleNamespace(source_timestamp=t))
                for n, t in out]  # fmt: skip


class _QueuedBus:
    def __init__(self) -> None:
        self.queue = _Queued()

    def writer(self, *_):
        from types import SimpleNamespace

        return SimpleNamespace(write=lambda msg: None)

    def reader(self, *_):
        return self.queue


@pytest.mark.parametrize("offset_s", [0.0, 5.0, -5.0])
def test_beats_read_late_count_from_when_they_were_sent_whatever_the_sender_s_clock(offset_s):
    """A monitor that stalls past the timeout reads the queued beats of a member that died
    meanwhile: that member is gone at once, not alive for another timeout; one still beating is
    kept. The members' clocks may be seconds off ours."""
    bus = _QueuedBus()
    group = MonitorGroup(bus, GroupConfig("a", heartbeat_s=0.05, timeout_s=0.4), ARMS)
    skew = int(offset_s * 1e9)
    now = time.monotonic()
    for name in ("b", "c"):  # heard promptly: the least age of each member's beats
        bus.queue.beats.append((name, time.time_ns() + skew))
    group.update(now)
    assert group.members(now) == ["a", "b", "c"]
    # b beat once more and died; a stalled 1 s (2.5 timeouts); c beat just before a woke
    bus.queue.beats += [("b", time.time_ns() + skew - int(1.0e9)), ("c", time.time_ns() + skew)]
    later = now + 1.0
    group.update(later)
    assert group.members(later) == ["a", "c"]
