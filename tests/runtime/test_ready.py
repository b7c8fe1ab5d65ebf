"""The ready models the wheel ships (ready_models/): each matches the schema and the profile its
name promises, they fit the wheel's budget, a name addresses one, and the stock model diagnoses
the shipped sample log with no training."""

from __future__ import annotations

import pytest

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import ready_dir
from robohealth_mj.monitor import main as monitor
from robohealth_mj.runtime.metadata import read_metadata
from robohealth_mj.runtime.ready import SAMPLE_FILE, ready_names, resolve_file, resolve_model

READY = ("full", "stock", "ur_driver")  # the name of each is the sensing profile it reads
BUDGET_BYTES = 5_000_000


@pytest.mark.parametrize("name", READY)
def test_each_ready_model_reads_this_schema_and_the_profile_its_name_says(name):
    meta = read_metadata(ready_dir() / f"{name}.onnx")
    # made under schema 2.0, read as the six-joint UR graph it is (the ready models are UR models)
    assert meta["schema_version"] in schema.READABLE_VERSIONS
    assert meta["arm_graph"] == schema.UR_GRAPH and meta["node_names"] == list(schema.NODE_NAMES)
    assert meta["sensing"] == name and int(meta["window"]) == 32
    card = (ready_dir() / f"{name}.md").read_text()
    assert meta["model_id"] in card and "## Commission it on your arm" in card


def test_the_ready_models_and_the_sample_fit_the_wheels_budget():
    assert ready_names() == sorted(READY)
    shipped = [p for p in ready_dir().iterdir() if p.suffix in (".onnx", ".md", ".csv")]
    assert sum(p.stat().st_size for p in shipped) <= BUDGET_BYTES


def test_a_name_is_a_ready_model_and_a_file_of_that_name_comes_first(tmp_path, monkeypatch):
    assert resolve_model("stock") == str(ready_dir() / "stock.onnx")
    assert resolve_file("sample") == str(ready_dir() / SAMPLE_FILE)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "stock").write_text("mine")
    assert resolve_model("stock") == "stock"
    with pytest.raises(InputError, match="model=stok: no such file, and not a ready model"):
        resolve_model("stok")


def test_the_stock_model_diagnoses_the_sample_log_by_name(capsys):
    """``monitor model=stock file=sample``: the sample (healthy, then friction at a joint from
    t = 20 s) is replayed and diagnosed; the friction is called, and only after it started."""
    monitor(["model=stock", "file=sample"])
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("t=")]
    assert lines and all(": no model" not in line for line in lines)
    called = [float(line[2:].split("s")[0]) for line in lines if ": friction @" in line]
    assert called and min(called) >= 20.0
