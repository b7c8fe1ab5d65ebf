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


def test_the_fleet_default_keeps_the_headlines_detections_on_a_session_it_never_saw(tmp_path):
    """The cost frontier's deployment default (``decide_every`` of conf/monitor.yaml, the model
    run on an arm every k-th tick) against the headline as it ran before (every tick), the ready
    ``full`` model both times, on a simulated session of every fault mode at severity 0.9 on one
    joint: it detects what the headline detects (a floor of one episode) and decides nearly as
    well tick by tick."""
    from robohealth_mj.common.config import compose_config

    every = compose_config("monitor", []).decide_every
    assert every > 1  # the default buys its streams by deciding every k-th tick
    session = ('"seed=77","faults.schedule.fault_s=4.0","faults.schedule.healthy_s=3.0",'
               '"faults.schedule.severities=[0.9]","faults.schedule.joints=[elbow]"')  # fmt: skip

    def run(k: int) -> dict:
        args = ["model=full", "source=sim", "duration_s=45", f"sim_overrides=[{session}]",
                "evaluate=true", "quiet=true", "threads=1", f"decide_every={k}",
                f"out={tmp_path / f'k{k}.json'}"]  # fmt: skip
        return monitor(args)

    headline, default = run(1), run(every)
    assert headline["episodes"] >= 5 and headline["alarms"]["detected"] >= 3  # the floor
    assert default["alarms"]["detected"] >= headline["alarms"]["detected"] - 1
    assert default["online_accuracy"] >= headline["online_accuracy"] - 0.05
    assert default["false_alarms"] <= headline["false_alarms"]
