"""The monitor on an SROS2-secured graph, on loopback: a keystore made without ROS; a secured
robot, monitor and dashboard that see every sample and every diagnosis; and each way in that
must stay shut (an unsecured publisher or subscriber, an identity from another CA, a publisher
whose permissions do not grant the topic) staying shut.

The secured participants run in the environment ``make setup-sros2`` builds (``.venv-sros2``:
the binding against Debian's Cyclone DDS, which has the security plugins); the unsecured ones
in this one, on PyPI's wheel. Without that environment these tests are skipped with the reason,
except under CI (``CI`` set), where its absence fails them.
"""

from __future__ import annotations

import itertools
import json
import os
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from robohealth_mj.ros2.keystore import (
    ENCLAVE_FILES,
    Grant,
    create_enclave,
    create_keystore,
    open_keystore,
)
from robohealth_mj.ros2.security import resolve_security

pytest.importorskip("cryptography", reason="keystores need cryptography: pip install '.[ros2]'")

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).parent
ARMS = ["arm1", "arm2"]
TICKS = 60
_DOMAINS = itertools.count(60 + os.getpid() % 20 * 2)


@pytest.fixture(scope="module")
def sros2_python() -> str:
    python = os.environ.get("ROBOHEALTH_SROS2_PYTHON", str(ROOT / ".venv-sros2" / "bin" / "python"))
    if not Path(python).is_file():
        message = f"no secured binding's environment at {python}: make setup-sros2"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return python


def _keystore(root: Path, domain: int, robot: Grant, monitor: Grant) -> Path:
    keystore = create_keystore(root, domain)
    create_enclave(keystore, "/robohealth/monitor", monitor)
    create_enclave(keystore, "/robohealth/robot", robot)
    create_enclave(keystore, "/dashboard", Grant(subscribe=("/diagnostics", "/*/health_diagnosis")))
    return root


def _grants(domain: int) -> tuple[Grant, Grant]:
    """The robot's and the monitor's grants as ``python -m robohealth_mj.keystore`` makes them."""
    from robohealth_mj.common.config import compose_config
    from robohealth_mj.ros2.grants import monitor_grant, robot_grant

    cfg = compose_config("keystore", [f"ros2.arms=[{','.join(ARMS)}]", f"ros2.domain_id={domain}"])
    return robot_grant(cfg.ros2), monitor_grant(cfg.ros2)


@pytest.fixture(scope="module")
def graph(tmp_path_factory, deployed) -> dict:
    """One domain's keystore (robot, monitor, dashboard), another CA's keystore with a robot
    enclave, and a robot whose grant names other arms' topics only; a short recording."""
    root = tmp_path_factory.mktemp("sros2")
    domain = next(_DOMAINS)
    robot, monitor = _grants(domain)
    keys = _keystore(root / "keys", domain, robot, monitor)
    narrow = Grant(publish=tuple(t.replace("/arm", "/other_arm") for t in robot.publish))
    create_enclave(open_keystore(keys, domain), "/robohealth/narrow", narrow)
    intruder = _keystore(root / "other_ca", domain, robot, monitor)
    lines = deployed["heldout"].read_text().splitlines(keepends=True)[:TICKS]
    recording = root / "short.jsonl"
    recording.write_text("".join(lines))
    return {"domain": domain, "keys": keys, "intruder": intruder, "recording": recording,
            "model": str(deployed["structural_onnx"]), "root": root}  # fmt: skip


def _env(keystore: Path | None, enclave: str | None = None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_SECURITY_")}
    if keystore is not None:
        env |= {"ROS_SECURITY_ENABLE": "true", "ROS_SECURITY_STRATEGY": "Enforce",
                "ROS_SECURITY_KEYSTORE": str(keystore)}  # fmt: skip
        if enclave:
            env["ROS_SECURITY_ENCLAVE_OVERRIDE"] = enclave
    return env


def _common(graph: dict) -> list[str]:
    return [f"ros2.domain_id={graph['domain']}", "ros2.interface=127.0.0.1",
            f"ros2.arms=[{','.join(ARMS)}]", "ros2.depth=200"]  # fmt: skip


def _run(graph: dict, monitor_python: str, robot: tuple[str, dict], listener: tuple[str, dict],
         reaches: bool = True, heard: bool = True) -> dict:  # fmt: skip
    """A monitor (secured, in ``monitor_python``), a dashboard and a robot replaying the
    recording on both arms: what the monitor diagnosed, what the dashboard heard, the robot's
    exit status and output. ``reaches``: whether the robot's samples should reach the monitor
    (the robot waits up to 8 s for its subscribers' match; a robot that should not reach it
    waits 2 s, and the rest stop 2 s after it); ``heard``: whether the dashboard should hear
    the diagnoses (else it stops 2 s after the robot)."""
    out = graph["root"] / f"heard_{next(_DOMAINS)}.json"
    monitor = subprocess.Popen(
        [monitor_python, "-m", "robohealth_mj.monitor", f"model={graph['model']}", "source=ros2",
         "duration_s=0", "ros2.reliable_subscriptions=true", *_common(graph)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=ROOT,
        env=_env(graph["keys"]),
    )  # fmt: skip
    dash = None
    try:
        first = monitor.stdout.readline()
        assert first.startswith("ros2 monitor:"), first + monitor.communicate()[0]
        dash = subprocess.Popen(
            [listener[0], str(HERE / "diagnosis_listener.py"), str(graph["domain"]), "25",
             str(TICKS), str(out), *ARMS],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=ROOT, env=listener[1],
        )  # fmt: skip
        assert dash.stdout.readline().startswith("listening"), dash.communicate()[0]
        robot_run = subprocess.run(
            [robot[0], "-m", "robohealth_mj.robot", "source=replay", f"file={graph['recording']}",
             "speed=4", f"discovery_s={8 if reaches else 2}", *_common(graph)],
            capture_output=True, text=True, cwd=ROOT, env=robot[1], timeout=120,
        )  # fmt: skip
        if not (reaches and heard):  # nothing should come: a grace period, then it stops
            time.sleep(2)
            dash.terminate()
        dash.communicate(timeout=60)
        monitor.terminate()
        said = monitor.communicate(timeout=60)[0]
    finally:
        for proc in (monitor, dash):
            if proc is not None and proc.poll() is None:
                proc.kill()
    diagnosed = {}
    for line in said.splitlines():
        arm, _, rest = line.partition(": ")
        if arm in ARMS and "samples diagnosed" in rest:
            diagnosed[arm] = int(rest.split()[0])
    assert monitor.returncode == 0, said
    return {"diagnosed": diagnosed, "heard": json.loads(out.read_text()), "monitor": first + said,
            "robot": robot_run}  # fmt: skip


# --- the keystore ---------------------------------------------------------------------------


def test_a_keystore_has_sros2_s_layout_owner_only_files_and_signed_grants(tmp_path):
    from cryptography import x509

    keys = _keystore(tmp_path / "keys", 7, Grant(publish=("/arm1/*",)), Grant.everything())
    folder = keys / "enclaves" / "robohealth" / "monitor"
    assert set(ENCLAVE_FILES) <= {p.name for p in folder.iterdir()}
    assert (folder / "identity_ca.cert.pem").resolve() == (keys / "public" / "ca.cert.pem")
    assert (keys / "private" / "identity_ca.key.pem").resolve() == keys / "private" / "ca.key.pem"
    for path in keys.rglob("*"):
        if path.is_symlink():
            continue
        mode = stat.S_IMODE(path.stat().st_mode)
        assert mode == (0o700 if path.is_dir() else 0o600), (path, oct(mode))
    cert = x509.load_pem_x509_certificate((folder / "cert.pem").read_bytes())
    assert cert.subject.rfc4514_string() == "CN=/robohealth/monitor"
    assert cert.issuer.rfc4514_string() == "CN=sros2CA"
    robot = (keys / "enclaves" / "robohealth" / "robot" / "permissions.xml").read_text()
    assert "<topic>rt/arm1/*</topic>" in robot and "<subscribe>" not in robot.split("ros_disc")[0]
    assert "<id>7</id>" in robot and "<default>DENY</default>" in robot
    # the signature carries the document it signs, in clear (what the plugins verify)
    assert "CN=/robohealth/robot" in (folder.parent / "robot" / "permissions.p7s").read_text()


def test_the_monitor_s_grant_reads_the_arms_topics_and_writes_its_diagnoses_only():
    robot, monitor = _grants(3)
    assert set(monitor.publish) == {"/diagnostics", "/arm1/health_diagnosis",
                                    "/arm2/health_diagnosis"}  # fmt: skip
    assert set(monitor.subscribe) == set(robot.publish)
    assert "/arm1/joint_states" in robot.publish and "/arm2/fault_state" in robot.publish
    assert not robot.subscribe and not any("*" in t for t in monitor.subscribe + monitor.publish)


def test_the_keystore_command_makes_a_keystore_then_enclaves_and_refuses_a_bad_one(tmp_path):
    keys = tmp_path / "keys"
    command = [sys.executable, "-m", "robohealth_mj.keystore", f"keystore={keys}"]
    made = subprocess.run([*command, "ros2.domain_id=5"], capture_output=True, text=True, cwd=ROOT)
    assert made.returncode == 0 and "made" in made.stdout, made.stderr
    enclave = subprocess.run(
        [*command, "ros2.domain_id=5", "enclave=/robohealth/monitor", "ros2.count=3"],
        capture_output=True, text=True, cwd=ROOT,
    )  # fmt: skip
    assert enclave.returncode == 0, enclave.stderr
    assert "publish 4 topics" in enclave.stdout  # /diagnostics and three health topics
    for bad, says in (
        (["ros2.domain_id=5", "enclave=not a namespace"], "a ROS namespace"),
        (["ros2.domain_id=6", "enclave=/x"], "rules domain 5, not 6"),
        (["ros2.domain_id=5", "enclave=/x", "grant=topics"], "grant.publish"),
    ):
        refused = subprocess.run([*command, *bad], capture_output=True, text=True, cwd=ROOT)
        assert refused.returncode == 2, refused.stderr
        assert len(refused.stderr.strip().splitlines()) == 1 and says in refused.stderr


# --- resolving the enclave as ROS 2 does ------------------------------------------------------


def test_security_is_read_from_the_environment_as_ros_2_reads_it(tmp_path, capsys):
    keys = _keystore(tmp_path / "keys", 4, Grant(), Grant())
    env = {"ROS_SECURITY_ENABLE": "true", "ROS_SECURITY_KEYSTORE": str(keys),
           "ROS_SECURITY_STRATEGY": "Enforce"}  # fmt: skip
    assert resolve_security({}, 4, {**env, "ROS_SECURITY_ENABLE": "True"}) is None  # exactly "true"
    assert resolve_security({"enable": False}, 4, env) is None  # the setting wins
    from robohealth_mj.common.errors import InputError

    with pytest.raises(InputError, match="no enclave /nowhere"):
        resolve_security({"enclave": "/nowhere"}, 4, env)
    with pytest.raises(InputError, match="names domain 4, not domain 9"):
        resolve_security({"enclave": "/robohealth/monitor"}, 9, env)
    with pytest.raises(InputError, match="no keystore"):
        resolve_security({}, 4, {"ROS_SECURITY_ENABLE": "true", "ROS_SECURITY_STRATEGY": "Enforce"})
    # Permissive (anything but Enforce): one line, and the participant joins unsecured
    assert (
        resolve_security({"enclave": "/nowhere"}, 4, {**env, "ROS_SECURITY_STRATEGY": "x"}) is None
    )
    assert "(Permissive): keystore" in capsys.readouterr().err
    # the enclave override wins over the configured enclave, as in ROS 2
    override = {**env, "ROS_SECURITY_ENCLAVE_OVERRIDE": "/nowhere"}
    with pytest.raises(InputError, match="no enclave /nowhere"):
        resolve_security({"enclave": "/robohealth/monitor"}, 4, override)


def test_a_monitor_on_the_plain_wheel_asked_for_enforced_security_says_so_in_one_line(tmp_path):
    """PyPI's binding has no DDS Security: never a silent open participant."""
    pytest.importorskip("cyclonedds")
    from robohealth_mj.ros2.security import binding_has_security

    if binding_has_security():
        pytest.skip("this environment's binding has DDS Security")
    keys = _keystore(tmp_path / "keys", 11, Grant(), Grant())
    run = subprocess.run(
        [sys.executable, "-m", "robohealth_mj.monitor", "model=full", "source=ros2",
         "duration_s=1", "ros2.domain_id=11", "ros2.interface=127.0.0.1"],
        capture_output=True, text=True, cwd=ROOT, env=_env(keys), timeout=120,
    )  # fmt: skip
    assert run.returncode == 2, run.stdout + run.stderr
    assert len(run.stderr.strip().splitlines()) == 1
    assert "has no DDS Security: cyclonedds 11" in run.stderr and "setup-sros2" in run.stderr


def test_an_enforced_monitor_without_its_keystore_exits_2_naming_what_is_missing(
    tmp_path, sros2_python
):
    run = subprocess.run(
        [sros2_python, "-m", "robohealth_mj.monitor", "model=full", "source=ros2", "duration_s=1",
         "ros2.domain_id=12", "ros2.interface=127.0.0.1"],
        capture_output=True, text=True, cwd=ROOT, env=_env(tmp_path / "absent"), timeout=120,
    )  # fmt: skip
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert f"keystore {tmp_path / 'absent'}: no such folder" in run.stderr
    assert "ros2 monitor:" not in run.stdout  # no participant was made


# --- the secured graph ------------------------------------------------------------------------


def test_a_secured_robot_monitor_and_dashboard_see_every_sample_and_every_diagnosis(
    graph, sros2_python
):
    got = _run(graph, sros2_python, (sros2_python, _env(graph["keys"])),
               (sros2_python, _env(graph["keys"])))  # fmt: skip
    assert got["robot"].returncode == 0, got["robot"].stderr
    assert "secured as /robohealth/monitor" in got["monitor"].splitlines()[0]
    assert got["diagnosed"] == dict.fromkeys(ARMS, TICKS), got["monitor"]
    heard = got["heard"]
    assert heard["secured"]
    assert all(heard["heard"][f"/{arm}/health_diagnosis"] == TICKS for arm in ARMS), heard
    assert heard["heard"]["/diagnostics"] >= 1


def test_an_unsecured_publisher_reaches_no_diagnosis(graph, sros2_python):
    got = _run(graph, sros2_python, (sys.executable, _env(None)),
               (sros2_python, _env(graph["keys"])), reaches=False)  # fmt: skip
    assert got["robot"].returncode == 0, got["robot"].stderr  # it published, to no one
    assert got["diagnosed"] == dict.fromkeys(ARMS, 0), got["monitor"]
    assert got["heard"]["heard"]["/arm1/health_diagnosis"] == 0


def test_an_unsecured_subscriber_receives_no_diagnosis(graph, sros2_python):
    got = _run(graph, sros2_python, (sros2_python, _env(graph["keys"])),
               (sys.executable, _env(None)), heard=False)  # fmt: skip
    assert got["diagnosed"] == dict.fromkeys(ARMS, TICKS), got["monitor"]  # diagnoses were made
    assert not got["heard"]["secured"]
    assert sum(got["heard"]["heard"].values()) == 0, got["heard"]


def test_an_identity_signed_by_another_ca_is_refused(graph, sros2_python):
    got = _run(graph, sros2_python, (sros2_python, _env(graph["intruder"])),
               (sros2_python, _env(graph["keys"])), reaches=False)  # fmt: skip
    assert got["robot"].returncode == 0, got["robot"].stderr  # its own keystore is valid
    assert got["diagnosed"] == dict.fromkeys(ARMS, 0), got["monitor"]


def test_a_publisher_whose_permissions_do_not_grant_the_topic_is_refused(graph, sros2_python):
    got = _run(graph, sros2_python, (sros2_python, _env(graph["keys"], "/robohealth/narrow")),
               (sros2_python, _env(graph["keys"])), reaches=False)  # fmt: skip
    robot = got["robot"]
    assert robot.returncode == 2 and len(robot.stderr.strip().splitlines()) == 1, robot.stderr
    assert "enclave /robohealth/narrow may not use topic '/arm1/" in robot.stderr
    assert got["diagnosed"] == dict.fromkeys(ARMS, 0), got["monitor"]
