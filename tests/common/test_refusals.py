"""Every refusal is one line and exit status 2: a value of the wrong kind, a file that is not
text, a run with nothing to diagnose, a command whose extra is not installed; and
``python -m robohealth_mj`` lists every command."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import robohealth_mj
from robohealth_mj.__main__ import COMMANDS
from robohealth_mj.common.errors import missing_extra
from robohealth_mj.monitor import main as monitor

PACKAGE = Path(robohealth_mj.__file__).parent


def _one_line(capsys, status: SystemExit) -> str:
    assert status.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


@pytest.mark.parametrize(
    ("override", "said"),
    [
        ("speed=fast", "speed='fast': speed takes a number"),
        ("alarm.raise_after=abc", "alarm.raise_after='abc': alarm.raise_after takes a number"),
        ("alarm=3", "alarm=3: alarm takes a block of keys"),
        ("evaluate=maybe", "evaluate='maybe': evaluate takes true or false"),
        ("sim_overrides=7", "sim_overrides=7: sim_overrides takes a list"),
        ("threads=0", "threads: 0 is not a thread count (a positive integer or auto)"),
    ],
)
def test_a_value_of_the_wrong_kind_is_one_line_naming_its_key(capsys, override, said):
    with pytest.raises(SystemExit) as status:
        monitor([override, "source=replay", "file=nowhere.jsonl"])
    assert said in _one_line(capsys, status)


def test_a_number_where_a_number_goes_passes_the_kind_check(capsys, tmp_path):
    """``speed=0.5`` against a default of 0 is a number too: the run goes on to the file."""
    with pytest.raises(SystemExit) as status:
        monitor(["speed=0.5", "source=replay", f"file={tmp_path / 'absent.jsonl'}"])
    assert "absent.jsonl" in _one_line(capsys, status)


def test_a_binary_file_is_refused_naming_it(capsys, tmp_path):
    binary = tmp_path / "capture.jsonl"
    binary.write_bytes(b'{"t": 0}\n\xd5\xff\x00\x81 not text\n')
    with pytest.raises(SystemExit) as status:
        monitor(["source=replay", f"file={binary}", "quiet=true"])
    assert f"{binary}:2: not text" in _one_line(capsys, status)


def test_a_text_file_with_no_valid_sample_is_a_failed_run(capsys, tmp_path):
    text = tmp_path / "notes.jsonl"
    text.write_text("hello\nworld\n")
    with pytest.raises(SystemExit) as status:
        monitor(["source=replay", f"file={text}", "quiet=true"])
    assert f"{text}: no valid sample to diagnose" in _one_line(capsys, status)


def test_the_package_root_holds_thin_entry_points_only():
    """Every module at the package root is a command, and none is over 60 lines: its logic
    lives in the rooms below (a test of the layout, so a new command stays thin)."""
    long = {p.name: n for p in PACKAGE.glob("*.py") if (n := len(p.read_text().splitlines())) > 60}
    assert not long, long


def test_a_missing_module_names_the_extra_that_brings_it():
    try:
        raise RuntimeError("built") from ModuleNotFoundError(
            "No module named 'mujoco'", name="mujoco"
        )
    except RuntimeError as exc:
        line = str(missing_extra(exc))
    assert (
        line
        == "this needs the 'sim' extra (no module 'mujoco' here): pip install 'robohealth_mj[sim]'"
    )
    assert missing_extra(ModuleNotFoundError("x", name="our_own_typo")) is None


def test_the_listing_names_every_entry_point_once():
    roots = {p.stem for p in PACKAGE.glob("*.py")} - {"__init__", "__main__"}
    names = [name for name, _, _ in COMMANDS]
    assert sorted(names) == sorted(roots)
    done = subprocess.run(
        [sys.executable, "-m", "robohealth_mj"], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0
    assert all(f"  {name} " in done.stdout for name in names)


# What the deployment install lacks (the [sim] and [train] extras), blocked as a missing module.
_BLOCKED = ("torch", "torch_geometric", "lightgbm", "sklearn", "mujoco", "dm_control", "scipy",
            "matplotlib", "PIL", "imageio", "onnxscript", "tensorboard", "progpy")  # fmt: skip
_RUN = """
import runpy, sys
class _Missing:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {blocked!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
sys.meta_path.insert(0, _Missing())
sys.argv = {argv!r}
runpy.run_module({module!r}, run_name="__main__")
"""


def _on_the_deployment_install(module: str, argv: list[str], cwd: Path):
    code = textwrap.dedent(_RUN.format(blocked=_BLOCKED, argv=argv, module=module))
    return subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True, timeout=120
    )


@pytest.mark.parametrize(("name", "extra"), [(n, e) for n, e, _ in COMMANDS])
def test_every_command_on_the_deployment_install_runs_or_names_its_extra(name, extra, tmp_path):
    """``--help`` on the base install: it prints its help, or one line naming the extra the
    listing gives for it."""
    done = _on_the_deployment_install(f"robohealth_mj.{name}", [name, "--help"], tmp_path)
    if done.returncode == 0:
        assert done.stdout.strip()
        return
    assert done.returncode == 2, done.stderr[-1500:]
    line = done.stderr.strip()
    assert "\n" not in line and f"pip install 'robohealth_mj[{extra}]'" in line, line


def test_the_monitor_at_its_default_source_names_the_simulators_extra(tmp_path):
    done = _on_the_deployment_install("robohealth_mj.monitor", ["monitor"], tmp_path)
    assert done.returncode == 2
    assert done.stderr.strip().endswith("pip install 'robohealth_mj[sim]'"), done.stderr[-1500:]


@pytest.mark.parametrize("name", ["bag", "dataset", "report", "tune_alarms", "effects", "bench"])
def test_a_file_centred_commands_help_prints_its_page(name, capsys):
    """``--help`` on a flag-style command prints its usage page (examples included), the text
    that lives beside its parser, not a note about where the code is."""
    import importlib

    entry = importlib.import_module(f"robohealth_mj.{name}")
    with pytest.raises(SystemExit) as status:
        entry.main(["--help"])
    out = " ".join(capsys.readouterr().out.split())  # argparse may wrap the page
    first = " ".join(entry.__doc__.strip().splitlines()[0].split())  # the page's first line
    assert status.value.code == 0 and first in out and "live in" not in out
