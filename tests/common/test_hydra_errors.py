"""Every configured command is a Hydra app (common/config.run_tool): a bad override is a user
error, one line and exit status 2, whichever command it is given to; ``--help`` lists the keys;
a sweep (``-m``) runs each job; ``--config-dir`` adds a user's configs."""

from __future__ import annotations

import os

import pytest

from robohealth_mj import commission, evaluate, identify, monitor, record, render, robot, train
from robohealth_mj.common.config import run_tool

CASES = [
    (evaluate, "evaluate", ["bogus=1"], "bogus: no such key"),
    (train, "train", ["variant=bogus"], "Could not find 'variant/bogus'"),
    (train, "train", ["model=gat"], "model='gat': model takes a block of keys"),
    (record, "record", ["seed=[1"], "seed=[1:"),
    (record, "record", ["seed=abc"], "seed='abc': seed takes a number"),
    (monitor, "monitor", ["ros2.count=many"], "ros2.count='many': ros2.count takes a number"),
    (robot, "robot", ["nowhere=1"], "nowhere: no such key"),
    (commission, "commission", ["export=perhaps"], "export='perhaps': export takes true or false"),
    (render, "render", ["fps=[1]"], "fps=[1]: fps takes a number"),
    (identify, "identify", ["fit.x=1"], "fit.x"),
]


@pytest.mark.parametrize(("module", "prog", "argv", "named"), CASES, ids=[c[1] for c in CASES])
def test_a_bad_override_is_one_line_naming_it_with_status_2(
    module, prog, argv, named, monkeypatch, capsys, tmp_path
) -> None:
    monkeypatch.chdir(tmp_path)  # Hydra would make its run directory here
    monkeypatch.delenv("HYDRA_FULL_ERROR", raising=False)
    with pytest.raises(SystemExit) as stop:
        module.main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"{prog}: error: ") and named in err
    assert "full_key" not in err and "Config search path" not in err
    assert "HYDRA_FULL_ERROR" not in os.environ  # the setting is the call's alone


def test_a_bug_in_the_app_keeps_its_traceback_and_the_setting_comes_back(
    monkeypatch, tmp_path
) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("HYDRA_FULL_ERROR", "0")

    def task(cfg) -> None:
        assert os.environ["HYDRA_FULL_ERROR"] == "1"  # Hydra raises rather than reports
        raise KeyError("a bug")

    with pytest.raises(KeyError, match="a bug"):
        run_tool("evaluate", task, [])
    assert os.environ["HYDRA_FULL_ERROR"] == "0"


def test_help_lists_every_key_and_the_ros2_block(capsys) -> None:
    with pytest.raises(SystemExit) as status:
        monitor.main(["--help"])
    assert status.value.code == 0
    out = capsys.readouterr().out
    assert "python -m robohealth_mj.monitor key=value" in out
    assert "raise_after: 10" in out and "tick_hz: 20" in out  # the monitor's keys and ros2.*


def test_a_sweep_runs_each_job_and_a_config_dir_adds_a_users_configs(tmp_path, monkeypatch):
    """``-m`` gives each job its override; ``--config-dir`` finds a user's own ros2 block."""
    monkeypatch.chdir(tmp_path)
    seen: list[tuple[float, int]] = []
    users = tmp_path / "mine" / "ros2"
    users.mkdir(parents=True)
    (users / "cell.yaml").write_text("domain_id: 42\ncount: 3\n")

    def task(cfg):
        seen.append((cfg.speed, cfg.ros2.domain_id))
        return cfg.speed

    flags = ["-m", "--config-dir", str(tmp_path / "mine")]
    last = run_tool("monitor", task, [*flags, "speed=1,2", "ros2=cell"])
    assert seen == [(1, 42), (2, 42)] and last == 2
    assert not (tmp_path / ".hydra").exists()  # a tool that acts where called leaves no run dir
