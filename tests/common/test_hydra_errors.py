"""A bad override on a Hydra entry point is a user error: one line, exit status 2."""

from __future__ import annotations

import os
import sys

import pytest
from hydra.core.global_hydra import GlobalHydra

from robohealth_mj import evaluate, record, train
from robohealth_mj.common.config import run_hydra_app

CASES = [
    (evaluate, "evaluate", ["bogus=1"], "(Key 'bogus' is not in struct)"),
    (train, "train", ["variant=bogus"], "Could not find 'variant/bogus'"),
    (record, "record", ["seed=[1"], "seed=[1:"),
]


@pytest.mark.parametrize(("module", "prog", "argv", "named"), CASES, ids=[c[1] for c in CASES])
def test_a_bad_override_is_one_line_naming_it_with_status_2(
    module, prog, argv, named, monkeypatch, capsys, tmp_path
) -> None:
    monkeypatch.chdir(tmp_path)  # Hydra would make its run directory here
    monkeypatch.setattr(sys, "argv", [prog, *argv])
    monkeypatch.delenv("HYDRA_FULL_ERROR", raising=False)
    GlobalHydra.instance().clear()
    with pytest.raises(SystemExit) as stop:
        run_hydra_app(prog, module.main)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"{prog}: error: ") and named in err
    assert "full_key" not in err and "Config search path" not in err
    assert "HYDRA_FULL_ERROR" not in os.environ  # the setting is the call's alone


def test_a_bug_in_the_app_keeps_its_traceback_and_the_setting_comes_back(monkeypatch) -> None:
    monkeypatch.setenv("HYDRA_FULL_ERROR", "0")

    def app() -> None:
        assert os.environ["HYDRA_FULL_ERROR"] == "1"  # Hydra raises rather than reports
        raise KeyError("a bug")

    with pytest.raises(KeyError, match="a bug"):
        run_hydra_app("evaluate", app)
    assert os.environ["HYDRA_FULL_ERROR"] == "0"
