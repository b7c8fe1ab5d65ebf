"""A campaign's steps: a failing step stops the job with its own one line and one naming the
step, not a traceback of the subprocess call."""

from __future__ import annotations

import pytest

from robohealth_mj.common.steps import run_step


def test_a_failing_step_stops_the_job_in_one_line_with_its_status(capfd):
    with pytest.raises(SystemExit) as stop:
        run_step("robohealth_mj.identify", "arm=ur10e")  # no logs: the step's own usage error
    assert stop.value.code == 2
    out, err = capfd.readouterr()
    assert out.startswith("+ robohealth_mj.identify arm=ur10e")
    lines = err.strip().splitlines()
    assert lines[0].startswith("identify: error: ")
    assert (
        lines[-1] == "step `python -m robohealth_mj.identify` exited with status 2: stopped there"
    )
    assert "Traceback" not in err


def test_a_quiet_step_passes_on_success_without_a_word(capfd):
    run_step("json.tool", "--help", quiet=True)  # prints its usage on stdout, exits 0
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_a_quiet_step_still_shows_its_error(capfd):
    with pytest.raises(SystemExit):
        run_step("robohealth_mj.identify", "arm=ur10e", quiet=True)
    out, err = capfd.readouterr()
    assert out == "" and err.startswith("identify: error: ")
