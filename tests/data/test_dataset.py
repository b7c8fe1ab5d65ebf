"""The dataset tool: support statistics, the gate, merging, the figure, and bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from omegaconf import OmegaConf

from robohealth_mj.common.config import compose_config
from robohealth_mj.data.read import read_samples
from robohealth_mj.dataset import main as dataset_main
from robohealth_mj.recording.corpus import build_corpus, plan
from robohealth_mj.recording.recorder import GRAPHS_FILE, record_session
from robohealth_mj.schema import SCHEMA_VERSION

FAST_FAULTS = [
    "faults.schedule.fault_s=1.0",
    "faults.schedule.healthy_s=1.0",
    "faults.schedule.severities=[0.9]",
]


def _record(record_cfg, out: Path, *overrides: str) -> Path:
    record_session(record_cfg(*FAST_FAULTS, *overrides), out)
    return out / GRAPHS_FILE


@pytest.fixture(scope="module")
def full_pass(tmp_path_factory) -> Path:
    """One pass over 6 joints x 6 faults at severity 0.9 (72 s simulated)."""
    out = tmp_path_factory.mktemp("full")
    cfg = compose_config(
        "record", ["session.progress=false", *FAST_FAULTS, "session.passes=1", "seed=21"]
    )
    record_session(cfg, out)
    return out / GRAPHS_FILE


def test_summarize_reports_support_and_passes_a_complete_file(full_pass, tmp_path, capsys):
    assert dataset_main(["summarize", str(full_pass), "--json", str(tmp_path / "s.json")]) == 0
    out = capsys.readouterr().out
    assert "gate PASS" in out and "36 scenarios" in out
    (summary,) = json.loads((tmp_path / "s.json").read_text())
    assert summary["samples"] == 1440
    assert set(summary["classes"].values()) == {720, 120}  # none: 720; each fault: 120
    assert set(summary["faulted_per_joint"].values()) == {120}
    assert summary["severities"]["jam"] == {"0.9": 120}


def test_the_gate_rejects_a_file_with_a_class_missing(record_cfg, tmp_path, capsys):
    path = _record(
        record_cfg,
        tmp_path,
        "session.passes=1",
        "faults.schedule.classes=[backlash,friction,struct_weaken,sensor_drift,sensor_noise]",
    )
    assert dataset_main(["summarize", str(path)]) == 1
    assert "classes missing: jam" in capsys.readouterr().out


def test_the_gate_rejects_a_degenerate_joint_distribution_and_a_tiny_file(
    record_cfg, tmp_path, capsys
):
    path = _record(record_cfg, tmp_path / "a", "session.passes=2", "faults.schedule.joints=[elbow]")
    assert dataset_main(["summarize", str(path)]) == 1
    out = capsys.readouterr().out
    assert "degenerate joint-target distribution" in out and "shoulder_pan (0)" in out
    small = _record(record_cfg, tmp_path / "b", "session.duration_s=5")
    assert dataset_main(["summarize", str(small)]) == 1
    assert "too small: 100 samples" in capsys.readouterr().out


def test_merge_keeps_every_run_and_refuses_a_session_twice(record_cfg, tmp_path, capsys):
    a = _record(record_cfg, tmp_path / "a", "session.duration_s=3", "seed=1")
    b = _record(record_cfg, tmp_path / "b", "session.duration_s=4", "seed=2")
    merged = tmp_path / "merged.jsonl"
    assert dataset_main(["merge", str(a), str(b.parent), "--out", str(merged)]) == 0
    samples = list(read_samples(merged))
    assert len(samples) == 140
    manifest = json.loads(merged.with_name("merged.jsonl.manifest.json").read_text())
    assert len(manifest["recording_run_ids"]) == 2 and manifest["samples"] == 140
    assert [s["samples"] for s in manifest["sources"]] == [60, 80]
    assert merged.read_bytes() == a.read_bytes() + b.read_bytes()
    assert dataset_main(["merge", str(a), str(a), "--out", str(tmp_path / "dup.jsonl")]) == 2
    assert "already came from" in capsys.readouterr().err
    assert not (tmp_path / "dup.jsonl").exists()


def test_plot_writes_the_signature_figure(full_pass, tmp_path):
    out = tmp_path / "fig7.png"
    assert dataset_main(["summarize", str(full_pass), "--plot", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 20_000


def _corrupt(lines: list[str], kind: str) -> list[str]:
    obj = json.loads(lines[2])
    if kind == "truncated":
        return [*lines[:-1], lines[-1][:150]]
    if kind == "nan":
        obj["x"][7][3] = float("nan")
    elif kind == "inf":
        obj["x"][0][4] = float("inf")
    elif kind == "version":
        obj["schema_version"] = "0.1"
    elif kind == "missing":
        del obj["fault"]
    elif kind == "node_order":
        obj["nodes"] = obj["nodes"][1:] + obj["nodes"][:1]
    elif kind == "topology":
        obj["edge_index"] = [obj["edge_index"][0][2:], obj["edge_index"][1][2:]]
    lines[2] = json.dumps(obj) + "\n"
    return lines


@pytest.mark.parametrize(
    "kind, where",
    [
        ("truncated", ":10: field '<line>'"),
        ("nan", ":3: field 'x[shoulder_lift_sensor].vel'"),
        ("inf", ":3: field 'x[shoulder_pan].effort'"),
        ("version", ":3: field 'schema_version'"),
        ("missing", ":3: field 'fault'"),
        ("node_order", ":3: field 'nodes'"),
        ("topology", ":3: field 'edge_index'"),
    ],
)
def test_bad_input_names_file_line_and_field(record_cfg, tmp_path, capsys, kind, where):
    good = _record(record_cfg, tmp_path / "rec", "session.duration_s=0.5").read_text()
    bad = tmp_path / f"{kind}.jsonl"
    bad.write_text("".join(_corrupt(good.splitlines(keepends=True), kind)))
    assert dataset_main(["summarize", str(bad)]) == 2
    assert f"{bad}{where}" in capsys.readouterr().err


def test_standard_corpus_plan_has_the_thesis_roles():
    specs = plan(compose_config("corpus").corpus, [])
    roles = [s.role for s in specs]
    assert roles.count("train") == 12 and roles.count("heldout") == 1
    assert roles.count("probe_payload_high") == 1
    train = [s for s in specs if s.role == "train"]
    assert len({s.overrides[0] for s in train}) == 12  # distinct seeds
    assert len({tuple(o for o in s.overrides if "curriculum" in o) for s in train}) > 1
    assert len({tuple(o for o in s.overrides if "session." in o) for s in train}) > 1
    probe = next(s for s in specs if s.role == "probe_payload_high")
    assert "curriculum.payload_scales=[2.2]" in probe.overrides


def test_the_arms_corpus_validates_on_programmes_no_arm_trains_on():
    """A seed fixes the program and fault schedule of every arm of one joint count, so the
    sessions that choose a recipe for an arm left out of training take seeds no session of any
    arm trains on, and training's fault schedule."""
    specs = plan(compose_config("corpus", ["corpus=arms"]).corpus, [])
    seeds = {role: {s.overrides[0] for s in specs if s.role == role}
             for role in ("train", "validation", "heldout")}  # fmt: skip
    assert len(seeds["validation"]) >= 2
    assert not seeds["validation"] & (seeds["train"] | seeds["heldout"])

    def schedule(spec) -> list[str]:
        return [o for o in spec.overrides if o.startswith("faults.")]

    train = next(s for s in specs if s.role == "train")
    assert all(schedule(s) == schedule(train) for s in specs if s.role == "validation")


def _healthy_segment_starts(overrides: tuple[str, ...]) -> float:
    """Share of one fault pass's curriculum segment starts that fall in a healthy interval."""
    from hydra.utils import instantiate

    cfg = compose_config("record", list(overrides))
    schedule = instantiate(cfg.faults.schedule, tick_s=0.05, seed=0, _convert_="all")
    segment = round(cfg.curriculum.segment_s / 0.05)
    starts = range(0, schedule.pass_ticks, segment)
    return sum(schedule.interval_at(t).scenario is None for t in starts) / len(starts)


@pytest.mark.parametrize("corpus", ["standard", "quick"])
def test_training_sessions_hold_healthy_segment_starts(corpus):
    """A model must see a segment start (arm at rest, payload taken on) while healthy, or it
    learns that a segment start is a fault. The held-out replay keeps its schedule."""
    specs = plan(compose_config("corpus", [f"corpus={corpus}"]).corpus, [])
    train = [s for s in specs if s.role == "train"]
    heldout = next(s for s in specs if s.role == "heldout")
    assert all(_healthy_segment_starts(s.overrides) > 0.3 for s in train)
    assert _healthy_segment_starts(heldout.overrides) == 0.0


def test_corpus_records_roles_in_parallel_and_resumes(tmp_path):
    spec = OmegaConf.to_container(compose_config("corpus", ["corpus=quick"]).corpus)
    spec["train"].update(sessions=3, lengths=[{"duration_s": 2}])
    for role in ("heldout", "probe_payload_high"):
        spec[role]["length"] = {"duration_s": 2}
    corpus = OmegaConf.create(spec)
    index = build_corpus(corpus, tmp_path, jobs=2, extra=[], progress=False)
    assert {r: len(v) for r, v in index["roles"].items()} == {
        "train": 3,
        "heldout": 1,
        "probe_payload_high": 1,
    }
    first = {p: p.stat().st_mtime_ns for p in tmp_path.glob(f"*/{GRAPHS_FILE}")}
    assert len(first) == 5
    (tmp_path / "heldout_seed900" / "manifest.json").unlink()  # as if killed mid-session
    build_corpus(corpus, tmp_path, jobs=2, extra=[], progress=False)
    again = {p: p.stat().st_mtime_ns for p in tmp_path.glob(f"*/{GRAPHS_FILE}")}
    changed = [p.parent.name for p in first if first[p] != again[p]]
    assert changed == ["heldout_seed900"]
    # another fault model is another session: recorded anew, not reused
    build_corpus(corpus, tmp_path, jobs=2, extra=["faults.fault_model=hybrid"], progress=False)
    hybrid = {p: p.stat().st_mtime_ns for p in tmp_path.glob(f"*/{GRAPHS_FILE}")}
    assert all(hybrid[p] != again[p] for p in again)


def test_corpus_fault_model_and_quoted_record_overrides_compose():
    """The documented forms: ``fault_model=hybrid`` and a quoted ``record_overrides`` element."""
    cfg = compose_config("corpus", ["fault_model=hybrid", 'record_overrides=["faults.ramp_s=1.0"]'])
    assert cfg.fault_model == "hybrid" and list(cfg.record_overrides) == ["faults.ramp_s=1.0"]
    assert compose_config("corpus").fault_model == "physics"


def test_a_schema_1_recording_is_refused_naming_the_file_and_both_versions(tmp_path, capsys):
    old = tmp_path / "v1.jsonl"
    line = {"schema_version": "1.0", "recording_run_id": "old", "sample_index": 0, "t": 0.05}
    old.write_text(json.dumps(line) + "\n")
    assert dataset_main(["summarize", str(old)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(old) in err[0]
    assert "'1.0'" in err[0] and f"'{SCHEMA_VERSION}'" in err[0]
