"""A life: one recorded session per operating day, its manifest carrying the truth."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robohealth_mj.common.config import compose_config
from robohealth_mj.faults.wear import draw_path
from robohealth_mj.recording.lives import LIFE_FILE, build_lives, plan_lives
from robohealth_mj.recording.recorder import MANIFEST_FILE
from robohealth_mj.schema import JOINT_NAMES

TINY = [  # two wearing lives of a few 3-second days, one healthy life of two days
    "corpus=lives",
    "corpus.session_s=3.0",
    "corpus.roles.train_lives.lives=2",
    "corpus.roles.train_lives.modes=[friction,backlash]",
    "corpus.roles.train_lives.paths=[linear]",
    "corpus.roles.train_lives.design_days=[3,4]",
    "corpus.roles.train_lives.max_days=8",
    "corpus.roles.healthy_lives.lives=1",
    "corpus.roles.healthy_lives.max_days=2",
    "~corpus.roles.heldout_lives",
    "~corpus.roles.val_lives",
    "~corpus.roles.val_wide_lives",
    "~corpus.roles.val_healthy_lives",
    "~corpus.roles.fresh_lives",
    "~corpus.roles.fresh_healthy_lives",
]


@pytest.fixture(scope="module")
def lives(tmp_path_factory):
    cfg = compose_config("corpus", TINY)
    out = tmp_path_factory.mktemp("lives")
    index = build_lives(cfg.corpus, out, jobs=2, extra=[], progress=False)
    return cfg, out, index


def test_a_life_records_a_day_per_session_until_its_wear_crosses_the_threshold(lives):
    cfg, out, index = lives
    entry = index["roles"]["train_lives"][0]
    life = json.loads((out / entry["life"]).read_text())
    assert life["status"] == "complete" and not life["censored"]
    assert life["failure_day"] == len(life["days"]) >= 2
    j = life["spec"]["joint"]
    wear = [d["severity"][j] for d in life["days"]]
    assert wear[0] == 0.0 and np.all(np.diff(wear) > 0) and wear[-1] < cfg.corpus.threshold
    for d in life["days"]:  # the other joints stay healthy
        assert all(v == 0.0 for k, v in d["severity"].items() if k != j)
    # the severity follows the path at the usage accumulated before the day
    path = draw_path("linear", cfg.corpus.threshold, np.random.default_rng(0))
    used = np.cumsum([0.0] + [d["usage"][j] for d in life["days"]])[:-1]
    assert wear == pytest.approx([path.severity(u / life["design_usage"]) for u in used], abs=1e-5)


def test_every_day_is_recorded_at_the_severity_its_manifest_says(lives):
    _, out, index = lives
    entry = index["roles"]["train_lives"][1]
    life = json.loads((out / entry["life"]).read_text())
    j = life["spec"]["joint"]
    for d in life["days"]:
        manifest = json.loads((out / entry["dir"] / d["dir"] / MANIFEST_FILE).read_text())
        schedule = manifest["faults"]["schedule"]
        if d["severity"][j] == 0.0:
            assert schedule["kind"] == "none"
        else:
            assert schedule["scenario"]["fault_class"] == life["spec"]["mode"]
            assert schedule["scenario"]["joint"] == JOINT_NAMES.index(j)
            assert schedule["scenario"]["severity"] == pytest.approx(d["severity"][j], abs=1e-6)


def test_a_healthy_life_runs_its_days_unworn(lives):
    _, out, index = lives
    entry = index["roles"]["healthy_lives"][0]
    life = json.loads((out / entry["life"]).read_text())
    assert len(life["days"]) == 2 and life["failure_day"] is None and not life["censored"]
    assert all(v == 0.0 for d in life["days"] for v in d["severity"].values())


def test_the_same_seeds_give_the_same_life_and_a_finished_life_is_kept(lives):
    cfg, out, index = lives
    again = build_lives(cfg.corpus, out, jobs=1, extra=[], progress=False)
    assert again["roles"] == index["roles"]
    entry = index["roles"]["train_lives"][0]
    first = json.loads((out / entry["life"]).read_text())
    (out / entry["dir"] / LIFE_FILE).unlink()  # redo the life: the kept days give the same truth
    build_lives(cfg.corpus, out, jobs=1, extra=[], progress=False)
    redone = json.loads((out / entry["life"]).read_text())
    assert redone["days"] == first["days"]


def test_a_life_of_an_unknown_mode_is_refused_in_one_line():
    cfg = compose_config("corpus", [*TINY, "corpus.roles.train_lives.modes=[sensor_noise]"])
    with pytest.raises(Exception, match="wear no mechanism"):
        plan_lives(cfg.corpus)


def test_the_corpus_command_records_lives_from_the_config_builder(tmp_path):
    """``python -m robohealth_mj.corpus corpus=lives``: the config's builder records lives."""
    import subprocess
    import sys

    args = [a for a in TINY if "train_lives" not in a or "lives=" not in a]
    one = ["corpus.roles.train_lives.lives=1", "corpus.roles.train_lives.max_days=3"]
    cmd = [sys.executable, "-m", "robohealth_mj.corpus", *args, *one, f"out_dir={tmp_path}",
           "progress=false"]  # fmt: skip
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "train_lives            1 life(s)" in out.stdout
    index = json.loads((tmp_path / "corpus.json").read_text())
    assert index["kind"] == "lives" and set(index["roles"]) == {"train_lives", "healthy_lives"}
