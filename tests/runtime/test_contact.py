"""The contact watch: a push on an arm that holds a pose is called while it lasts, at the joint
nearest it, and nothing else is: not a commanded move, not the rest after a push."""

from __future__ import annotations

import json
from collections import Counter

import numpy as np
import pytest

from robohealth_mj import schema
from robohealth_mj.common.config import compose_config
from robohealth_mj.common.errors import InputError
from robohealth_mj.recording.recorder import build_simulator, chunk_features
from robohealth_mj.runtime.contact import (
    ContactBank,
    ContactPolicy,
    Placing,
    commission_thresholds,
    contact_metadata,
)
from robohealth_mj.sim.contact_surface import arm_surface
from robohealth_mj.sim.pushes import joint_moving, read_pushes

J = schema.N_JOINTS
VEL, EFFORT, RESIDUAL = (schema.feature_index(n) for n in ("vel", "effort", "effort_residual"))
HOLD = ["arm=ur10e", "session.progress=false", "faults=none", "curriculum.families=[hold]"]
PUSH_TICKS = range(120, 137)  # at 6 s for 0.8 s, 20 Hz (shorter than half the level's span)


def _hold(pushes: str = "[]", seconds: float = 10.0) -> tuple[np.ndarray, object]:
    """Raw snapshots ``[T, 12, F]`` of a simulated UR10e that moves to a pose and holds it."""
    sim = build_simulator(compose_config("record", [*HOLD, f"session.pushes={pushes}"]))
    chunks = [chunk_features(c) for c in sim.run(round(seconds / sim.tick_s))]
    return np.concatenate(chunks), sim


def _watch(x: np.ndarray, policy: ContactPolicy, threshold: np.ndarray) -> list[int]:
    """The joint called per tick, -1 for none."""
    bank, slot = ContactBank(policy, threshold, "ur10e", 1), np.zeros(1, np.int64)
    return [int(bank.update(slot, tick[None])[1][0]) for tick in x]


@pytest.fixture(scope="module")
def commissioned() -> np.ndarray:
    healthy, _ = _hold()
    threshold, _ = commission_thresholds([healthy], "ur10e", 2.0)
    assert threshold is not None
    return threshold


# a force across each link's own joint axis (link frame: the joint turns about z)
PUSHES = {
    "forearm_link": "{force_n: [0, 60, 0], point_m: [-0.3, 0, 0.068]}",
    "wrist_2_link": "{force_n: [0, 30, 0], point_m: [0.1, 0, 0]}",
}


@pytest.mark.parametrize("link", sorted(PUSHES))
def test_a_push_on_a_held_pose_is_called_while_it_lasts_at_the_joint_nearest_it(link, commissioned):
    push = PUSHES[link].replace("{", f"{{at_s: 6, for_s: 0.8, link: {link}, ", 1)
    x, sim = _hold(f"[{push}]")
    called = _watch(x, ContactPolicy(), commissioned)
    during = [j for k, j in enumerate(called) if k in PUSH_TICKS and j >= 0]
    assert len(during) >= 0.75 * len(PUSH_TICKS)  # all but the force's rise and the confirming
    named = Counter(during).most_common(1)[0][0]
    assert schema.JOINT_NAMES[named] == joint_moving(sim.model, link)
    assert all(j < 0 for k, j in enumerate(called) if k not in range(120, 140))  # nor after


def _still(ticks: int, model_nm: float = 20.0) -> np.ndarray:
    """An arm at rest: model torque ``model_nm`` on every joint, a small residual noise."""
    x = np.zeros((ticks, schema.N_NODES, schema.N_FEATURES), np.float32)
    x[:, :J, RESIDUAL] = 0.05 * np.random.default_rng(0).standard_normal((ticks, J))
    x[:, :J, EFFORT] = model_nm + x[:, :J, RESIDUAL]
    return x


def _push(x: np.ndarray, ticks: slice, joints: list[int], nm: float = 5.0) -> np.ndarray:
    x = x.copy()
    x[ticks, joints, RESIDUAL] += nm
    x[ticks, joints, EFFORT] += nm  # the drive pushes back; the controller's model stays put
    return x


THRESHOLD = np.full(J, 1.0)


def test_the_joint_named_is_the_most_distal_one_loaded():
    called = _watch(_push(_still(200), slice(100, 130), [0, 1, 2]), ContactPolicy(), THRESHOLD)
    assert {j for j in called[104:130]} == {2} and all(j < 0 for j in called[:100])


def test_a_commanded_move_is_no_contact_but_a_push_is():
    x = _still(200)
    x[100:130, :J, EFFORT] += 5.0  # the controller commands a move: its model torque changes
    x[100:130, :J, RESIDUAL] += 5.0 * np.linspace(0, 1, 30)[:, None]  # breakaway friction
    assert all(j < 0 for j in _watch(x, ContactPolicy(), THRESHOLD))
    unguarded = ContactPolicy(command_share=np.inf)  # without the guard it would be one
    assert any(j >= 0 for j in _watch(x, unguarded, THRESHOLD))


def test_a_long_push_echoes_unless_its_ticks_are_left_out_of_the_level():
    long_push = _push(_still(300), slice(100, 135), [3])  # 1.75 s
    called = _watch(long_push, ContactPolicy(exclude_contact=True), THRESHOLD)
    assert all(j == 3 for j in called[104:135]) and all(j < 0 for j in called[135:])
    echo = _watch(long_push, ContactPolicy(), THRESHOLD)[135:]  # the default: it becomes the level
    assert any(j == 3 for j in echo)


@pytest.mark.parametrize("exclude", [False, True])
def test_a_lasting_offset_becomes_the_new_rest_and_the_next_push_is_read_against_it(exclude):
    policy = ContactPolicy(exclude_contact=exclude)
    stuck = _push(_still(400), slice(100, 400), [3])  # static friction holds the push's torque
    called = _watch(stuck, policy, THRESHOLD)
    assert all(j == 3 for j in called[104:139]) and all(j < 0 for j in called[160:])
    again = _push(stuck, slice(165, 190), [1])
    called = _watch(again, policy, THRESHOLD)
    assert all(j == 1 for j in called[165 + policy.confirm - 1 : 190])


def test_a_stream_that_never_rests_long_enough_gets_no_thresholds():
    moving = _still(200)
    moving[:, :J, VEL] = 0.5
    threshold, why = commission_thresholds([moving], "ur10e", 2.0)
    assert threshold is None and "no quiet of 25 ticks" in why


def test_contact_policy_and_pushes_refuse_nonsense_in_one_line():
    for bad in ({"confirm": 0}, {"recent_ticks": 30, "settle_ticks": 25}, {"still_rad_s": 0}):
        with pytest.raises(ValueError):
            ContactPolicy(**bad)
    model = build_simulator(compose_config("record", HOLD)).model
    for entry, said in (
        ({"at_s": 1, "for_s": 1, "link": "elbow", "force_n": [0, 0, 1]}, "is not one of"),
        ({"at_s": 1, "for_s": 1, "link": "forearm_link"}, "key 'force_n' missing"),
        ({"at_s": 1, "for_s": 0, "link": "forearm_link", "force_n": [0, 0, 1]}, "for_s > 0"),
        ({"at_s": 1, "for_s": 1, "link": "forearm_link", "force_n": [0, 1]}, "[x, y, z]"),
    ):
        with pytest.raises(
            InputError, match=r"session\.pushes\[0\]: .*" + said.replace("[", r"\[")
        ):
            read_pushes([entry], model)


def test_a_model_s_contact_metadata_is_read_or_refused_in_one_line_naming_the_key():
    surface = arm_surface("ur10e")
    placing = Placing(surface, np.full(J, 0.5))
    good = {"contact_threshold_nm": json.dumps([1.0] * J),
            "contact_placing": json.dumps(placing.to_dict())}  # fmt: skip
    threshold, read = contact_metadata(good, "m.onnx")
    assert threshold.tolist() == [1.0] * J and len(read.surface.link) == len(surface.link)
    assert contact_metadata({}, "m.onnx") is None  # no watch
    assert contact_metadata({**good, "contact_placing": ""}, "m.onnx")[1] is None  # before placing
    short = placing.to_dict()
    short["surface"]["normal"] = short["surface"]["normal"][:-1]
    for bad, key, said in (
        ({**good, "contact_threshold_nm": "[1, 2"}, "contact_threshold_nm", "Expecting"),
        ({**good, "contact_threshold_nm": "[1, 2]"}, "contact_threshold_nm", "6 positive"),
        ({**good, "contact_placing": "{}"}, "contact_placing", "surface"),
        ({**good, "contact_placing": json.dumps(short)}, "contact_placing", "normal has shape"),
        ({**good, "contact_placing": json.dumps({**placing.to_dict(), "noise_nm": [1.0]})},
         "contact_placing", "one positive value per joint"),
    ):  # fmt: skip
        with pytest.raises(InputError, match=f"^m.onnx: metadata '{key}' cannot be read: .*{said}"):
            contact_metadata(bad, "m.onnx")


def test_bench_contact_times_a_resting_fleet_per_stream_count(capsys):
    from robohealth_mj.bench import main as bench_main

    bench_main(["contact", "--streams", "3", "20"])
    out = capsys.readouterr().out.splitlines()
    rows = [line for line in out if line[2:3].isdigit()]
    assert [row.split(" | ")[0] for row in rows] == ["| 3", "| 20"]
    assert all(float(row.split(" | ")[1]) > 0 for row in rows)
    placing = [line for line in out if line.startswith("| one placement")]
    assert len(placing) == 1 and float(placing[0].split(" | ")[1]) > 0


def test_a_push_square_on_the_flange_is_placed_there_where_the_model_carries_the_surface():
    """The flange pushed square on its side: wrist 3 is not loaded, so the most distal joint over
    its threshold is wrist 2; with the arm's chain and surface the watch names wrist 3."""
    surface = arm_surface("ur10e")
    pose = np.array([-0.28, -1.95, -1.67, -1.53, 0.99, 0.39])
    lever, normal = surface.lever(pose)
    point = np.flatnonzero(surface.link == 5)[3]  # the flange's side, through wrist 3's axis
    external = lever[point] @ (-40.0 * normal[point])  # N·m: 40 N square on
    assert abs(external[5]) < 1e-9
    x = _still(200)
    x[:, :J, schema.feature_index("pos")] = pose
    x[100:116, :J, RESIDUAL] -= external  # the drives hold against the push (0.8 s)
    x[100:116, :J, EFFORT] -= external
    noise = np.array([5.8, 10.2, 1.7, 0.56, 0.71, 2.0])
    threshold = 2.0 * noise
    plain = ContactBank(ContactPolicy(), threshold, "ur10e", 1)
    placing = ContactBank(ContactPolicy(), threshold, "ur10e", 1, Placing(surface, noise))
    slot = np.zeros(1, np.int64)
    named = {
        "plain": [int(plain.update(slot, t[None])[1][0]) for t in x],
        "placed": [int(placing.update(slot, t[None])[1][0]) for t in x],
    }
    assert set(named["plain"][103:116]) == {4} and set(named["placed"][103:116]) == {5}
    assert all(j < 0 for j in named["placed"][:103] + named["placed"][116:])


def test_a_contact_no_single_push_explains_keeps_the_most_distal_joint_over_its_threshold():
    """Wrist 2 alone kicked, nothing upstream: no push on any link gives that, so the watch names
    the most distal joint over its threshold rather than nothing."""
    surface = arm_surface("ur10e")
    noise = np.array([5.8, 10.2, 1.7, 0.56, 0.71, 2.0])
    x = _still(200)
    x[:, :J, schema.feature_index("pos")] = [-0.28, -1.95, -1.67, -1.53, 0.99, 0.39]
    x = _push(x, slice(100, 116), [4], nm=30.0)
    bank = ContactBank(ContactPolicy(), 2.0 * noise, "ur10e", 1, Placing(surface, noise))
    slot = np.zeros(1, np.int64)
    named = [int(bank.update(slot, t[None])[1][0]) for t in x]
    assert set(named[103:116]) == {4}
