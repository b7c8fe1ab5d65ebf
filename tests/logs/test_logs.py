"""Controller logs in: UR RTDE CSV, the voraus-AD parquet layout and any table through a column
map, on small files these tests write (the voraus-AD data is CC BY-NC-SA, so its layout is
rebuilt here, not copied)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from robohealth_mj import schema
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.read import read_samples, recording_sensing
from robohealth_mj.ingest import main as ingest_main
from robohealth_mj.logs.convert import convert_log
from robohealth_mj.logs.rtde_writer import write_rtde_csv

J = schema.N_JOINTS
K_T = np.array([11.0, 11.5, 9.0, 4.2, 4.0, 3.8])  # N*m per A the tests' "controller" uses


def _rtde(t: np.ndarray) -> dict[str, np.ndarray]:
    """Columns of a UR RTDE recording whose joint signals are linear in time (so linear
    resampling is exact) and whose model torque is K_T x the target current."""
    cols = {"timestamp": t}
    t = t - np.floor(t[0])  # the controller's clock starts anywhere; the motion at 0
    for j in range(J):
        cols[f"target_q_{j}"] = 0.1 * j - 1.0 + 0.2 * t
        cols[f"actual_q_{j}"] = cols[f"target_q_{j}"] + 0.001 * (j + 1)
        cols[f"actual_qd_{j}"] = 0.2 + 0.01 * j * t
        cols[f"target_current_{j}"] = 0.5 + 0.1 * j + 0.05 * t
        cols[f"actual_current_{j}"] = cols[f"target_current_{j}"] + 0.02 * (j + 1)
        cols[f"target_moment_{j}"] = K_T[j] * cols[f"target_current_{j}"]
        cols[f"joint_temperatures_{j}"] = np.full_like(t, 31.0)  # a column no map reads
    return cols


def _write_csv(path: Path, cols: dict[str, np.ndarray], delimiter: str = " ") -> Path:
    names = list(cols)
    lines = [delimiter.join(names)]
    lines += [
        delimiter.join(f"{cols[n][i]:.9g}" for n in names) for i in range(len(cols[names[0]]))
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(("rate", "delimiter"), [(125.0, " "), (500.0, ","), (10.0, ",")])
def test_an_rtde_log_resamples_exactly_to_the_tick_rate(tmp_path, rate, delimiter):
    """UR's recorder (space-separated, 125 Hz) and ur_rtde's (comma, 500 Hz), and a 10 Hz log
    upsampled: each channel at each 20 Hz tick is the linear signal's value at that instant, the
    torque constant is fitted from the controller's own model torque."""
    t = 1000.0 + np.arange(int(3.0 * rate) + 1) / rate
    log = _write_csv(tmp_path / "arm.csv", _rtde(t), delimiter)
    cmap, (session,) = convert_log(log)  # the map is found from the columns
    assert cmap.name == "ur_rtde"
    np.testing.assert_allclose(session.stats["torque_constant_nm_per_a"], K_T, rtol=1e-6)
    assert len(session.t) == 61 and np.array_equal(session.sample_index, np.arange(61))
    tick = 1000.0 + np.arange(61) / 20.0
    np.testing.assert_allclose(session.t, tick)
    expected = _rtde(tick)
    for j in range(J):
        s = session.state[:, j]
        np.testing.assert_allclose(s[:, 0], expected[f"actual_q_{j}"], atol=1e-7)
        np.testing.assert_allclose(s[:, 1], expected[f"actual_qd_{j}"], atol=1e-7)
        np.testing.assert_allclose(s[:, 2], K_T[j] * expected[f"actual_current_{j}"], rtol=1e-6)
        np.testing.assert_allclose(s[:, 3], 0.001 * (j + 1), atol=1e-7)
        np.testing.assert_allclose(s[:, 4], K_T[j] * 0.02 * (j + 1), rtol=1e-5)


def test_ingest_writes_a_recording_every_reader_takes(tmp_path, capsys):
    t = np.arange(0, 4.0, 1 / 125.0)
    log = _write_csv(tmp_path / "cell3.csv", _rtde(t))
    assert ingest_main([str(log), "--map", "ur_rtde", "--out", str(tmp_path / "rec")]) == 0
    assert "cell3: 500 rows at 125 Hz -> 80 ticks" in capsys.readouterr().out
    rec = load_recordings([tmp_path / "rec" / "graphs.jsonl"])
    direct = load_recordings([log])  # the log read as it is, for monitor and evaluate
    np.testing.assert_allclose(rec.x, direct.x, rtol=1e-5, atol=1e-6)
    assert rec.run_ids == ["cell3"] and len(rec) == 80
    assert not rec.active.any() and not rec.x[:, J:, schema.SENSOR_CHANNELS].any()
    np.testing.assert_array_equal(
        rec.x[:, :J, schema.STATE_CHANNELS], rec.x[:, J:, schema.STATE_CHANNELS]
    )


def test_a_gap_in_the_log_breaks_the_sample_numbering(tmp_path):
    t = np.arange(0, 4.0, 1 / 125.0)
    keep = (t < 1.5) | (t > 2.0)  # half a second lost
    cols = {k: v[keep] for k, v in _rtde(t).items()}
    _, (session,) = convert_log(_write_csv(tmp_path / "gap.csv", cols))
    step = np.diff(session.sample_index)
    assert step.max() > 1 and (step >= 1).all()
    assert session.stats["ticks_in_gaps"] == int(np.sum(step - 1))


def test_the_voraus_ad_layout_reads_one_session_per_episode(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols: dict[str, list] = {"time": [], "sample": [], "anomaly": [], "category": []}
    for j in range(1, J + 1):
        for name in ("joint_position", "joint_velocity", "target_position", "motor_torque",
                     "target_torque", "motor_iq"):  # fmt: skip
            cols[f"{name}_{j}"] = []
    for episode in (0, 1):
        t = np.arange(0, 2.0, 0.01)  # 100 Hz, restarting each episode
        cols["time"] += t.tolist()
        cols["sample"] += [episode] * len(t)
        cols["anomaly"] += [bool(episode)] * len(t)
        cols["category"] += [episode] * len(t)
        for j in range(1, J + 1):
            cols[f"joint_position_{j}"] += (0.3 * t + j).tolist()
            cols[f"target_position_{j}"] += (0.3 * t + j - 0.002).tolist()
            cols[f"joint_velocity_{j}"] += [0.3] * len(t)
            cols[f"motor_torque_{j}"] += (2.0 * j + t).tolist()
            cols[f"target_torque_{j}"] += (2.0 * j + t - 0.5).tolist()
            cols[f"motor_iq_{j}"] += [1.0] * len(t)
    path = tmp_path / "voraus.parquet"
    pq.write_table(pa.table(cols), path)
    samples = list(read_samples(path))
    runs = sorted({s.recording_run_id for s in samples})
    assert runs == ["voraus-sample0", "voraus-sample1"]
    first = samples[0].x
    np.testing.assert_allclose(
        first[:J, schema.feature_index("pos")], np.arange(1, J + 1), atol=1e-6
    )
    np.testing.assert_allclose(first[:J, schema.feature_index("pos_error")], 0.002, atol=1e-6)
    np.testing.assert_allclose(first[:J, schema.feature_index("effort_residual")], 0.5, atol=1e-6)
    assert len(samples) == 2 * 40  # 2 s at 20 Hz per episode (the last tick at 1.95 s)


def test_a_generic_column_map_converts_degrees_and_milliamperes(tmp_path):
    t = np.arange(0, 2.0, 0.004)
    cols = {"time_s": t}
    for j in range(J):
        cols[f"q{j}_deg"] = np.full_like(t, 90.0)
        cols[f"cmd{j}_deg"] = np.full_like(t, 89.0)
        cols[f"w{j}_dps"] = np.full_like(t, 30.0)
        cols[f"i{j}_mA"] = np.full_like(t, 1500.0)
        cols[f"icmd{j}_mA"] = np.full_like(t, 1000.0)
    log = _write_csv(tmp_path / "other.csv", cols, ",")
    spec = tmp_path / "mine.yaml"
    spec.write_text(
        "name: mine\ntime: time_s\njoint_index: [0, 1, 2, 3, 4, 5]\n"
        "channels: {pos: 'q{j}_deg', vel: 'w{j}_dps', effort: 'i{j}_mA',"
        " pos_error: ['q{j}_deg', 'cmd{j}_deg'], effort_residual: ['i{j}_mA', 'icmd{j}_mA']}\n"
        "units: {pos: deg, vel: deg/s, effort: mA, pos_error: deg, effort_residual: mA}\n"
        "torque_constant: [10, 10, 10, 2, 2, 2]\n"
    )
    _, (s,) = convert_log(log, spec)
    np.testing.assert_allclose(s.state[0, 0], [np.pi / 2, np.pi / 6, 15.0, np.pi / 180, 5.0])
    np.testing.assert_allclose(s.state[0, 5, 2], 3.0)


def _bad(tmp_path: Path, capsys, edit, *extra: str) -> str:
    t = np.arange(0, 2.0, 0.008)
    cols = _rtde(t)
    edit(cols)
    log = _write_csv(tmp_path / "bad.csv", cols)
    status = ingest_main([str(log), *extra, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err and "Traceback" not in err
    assert not (tmp_path / "out" / "graphs.jsonl").exists()  # nothing half-written
    return err


def test_each_bad_log_gets_one_line_naming_file_column_and_line(tmp_path, capsys):
    def back_in_time(c):
        c["timestamp"][40] = c["timestamp"][38]

    def kiloamperes(c):
        c["actual_current_2"][7] = 2500.0

    def degrees(c):
        c["actual_q_4"] *= 180.0 / np.pi
        c["actual_q_4"] += 200.0

    def milliseconds(c):
        c["timestamp"] *= 1000.0

    def nan(c):
        c["actual_qd_1"][3] = np.nan

    err = _bad(tmp_path, capsys, back_in_time)
    assert "bad.csv: column 'timestamp': line 42: " in err and "time must increase" in err
    err = _bad(tmp_path, capsys, kiloamperes)
    assert "column 'actual_current_2': line 9: 2500 A is beyond" in err
    assert "column 'actual_q_4': line 2:" in _bad(tmp_path, capsys, degrees)
    assert "is the time in seconds?" in _bad(tmp_path, capsys, milliseconds)
    assert "column 'actual_qd_1': line 5: not a finite number" in _bad(tmp_path, capsys, nan)

    def no_current(c):
        del c["actual_current_3"]

    err = _bad(tmp_path, capsys, no_current, "--map", "ur_rtde")
    assert "column 'actual_current_3' missing" in err
    assert "no column map fits its columns" in _bad(tmp_path, capsys, no_current)
    spec = tmp_path / "odd.yaml"
    spec.write_text("time: t\njoint_index: [0,1,2,3,4,5]\nchannels: {torque: x}\nunits: {}\n")
    assert "key 'channels.torque': unknown" in _bad(
        tmp_path, capsys, lambda c: None, "--map", str(spec)
    )


def _as_rtde_log(x: np.ndarray, index: np.ndarray, path: Path, k_t: np.ndarray = K_T) -> Path:
    """A UR RTDE CSV carrying snapshots' ``[T, 12, F]`` joint channels at their 20 Hz ticks."""
    return write_rtde_csv(x, 0.05 * index.astype(np.float64), path, k_t)


def test_a_stock_model_diagnoses_a_log_as_it_diagnoses_the_recording(
    stock_deployed, deployed, tmp_path, capsys
):
    """The held-out session's joint channels written as a UR RTDE log: the stock model's
    decisions on the log equal those on the recording; the monitor replays the log with it,
    and refuses a model that reads the sensor package in one line."""
    from robohealth_mj.monitor import main as monitor_main
    from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime

    rec = load_recordings([stock_deployed["heldout"]])
    first = rec.run == 0
    rec_x, index = rec.x[first][:200], rec.sample_index[first][:200]
    assert np.array_equal(index, np.arange(index[0], index[0] + 200))
    log = _as_rtde_log(rec_x, index, tmp_path / "arm.csv")
    from_log = load_recordings([log]).x
    assert from_log.shape == rec_x.shape
    onnx = str(stock_deployed["onnx"])
    decided = []
    for data in (rec_x, from_log):
        fleet = FleetRuntime(onnx)
        slot = fleet.register(["arm"])
        probs = []
        for t in range(len(data)):
            r = fleet.step(slot, np.array([t]), np.array([0.05 * (t + 1)]), data[t : t + 1])
            if r.status[0] == DECIDED:
                probs.append(r.probs[0])
        decided.append(np.array(probs))
    np.testing.assert_allclose(decided[0], decided[1], atol=2e-3)
    assert np.array_equal(decided[0].argmax(1), decided[1].argmax(1))

    monitor_main([f"model={onnx}", "source=replay", f"file={log}", "quiet=true"])
    with pytest.raises(SystemExit) as done:
        monitor_main([f"model={deployed['structural_onnx']}", "source=replay", f"file={log}"])
    err = capsys.readouterr().err.strip()
    assert done.value.code == 2 and "\n" not in err
    assert "arm.csv: the data has the stock profile's channels and the model reads the full" in err


def test_a_log_without_target_position_is_read_with_the_reduced_profile(tmp_path, capsys):
    """A real RTDE log without ``target_q``: ingest picks stock_reduced, says what it dropped
    and why, zeroes the tracking error and keeps every other channel as the full log has it."""
    t = np.arange(0, 4.0, 1 / 125.0)
    full = _rtde(t)
    cols = {k: v for k, v in full.items() if not k.startswith("target_q_")}
    log = _write_csv(tmp_path / "no_target.csv", cols, ",")
    assert ingest_main([str(log), "--out", str(tmp_path / "rec")]) == 0
    out = capsys.readouterr().out
    assert "sensing profile stock_reduced: pos_error dropped (column 'target_q_0' missing)" in out
    manifest = json.loads((tmp_path / "rec" / "manifest.json").read_text())
    assert manifest["sensing"] == "stock_reduced" and "pos_error" in manifest["dropped"]
    assert recording_sensing(log) == "stock_reduced"
    assert recording_sensing(_write_csv(tmp_path / "full.csv", full, ",")) == "stock"
    reduced = load_recordings([log]).x
    whole = load_recordings([tmp_path / "full.csv"]).x
    err = schema.feature_index("pos_error")
    assert not reduced[..., err].any() and whole[:, :J, err].any()
    keep = [schema.feature_index(n) for n in ("pos", "vel", "effort", "effort_residual")]
    np.testing.assert_allclose(reduced[..., keep], whole[..., keep], rtol=1e-6)


def _headerless(log: Path, signals: tuple[str, ...]) -> tuple[Path, dict, np.ndarray]:
    """A 3 s, 100 Hz log of these per-joint signals after the time, with no header line."""
    t = np.arange(0, 3.0, 1 / 100.0)
    cols = _rtde(t)
    order = ["timestamp"] + [f"{c}_{j}" for c in signals for j in range(J)]
    log.write_text("\n".join(",".join(f"{cols[n][i]:.9g}" for n in order)
                             for i in range(len(t))) + "\n")  # fmt: skip
    return log, cols, t


def test_a_headerless_log_reads_through_the_map_that_names_its_columns(tmp_path, capsys):
    """The public UR10e identification layout: 31 numbers a row, no header line."""
    log, cols, t = _headerless(tmp_path / "ur-20_01_17-p1.csv", ("actual_q", "actual_qd",
                               "actual_current", "target_current", "target_moment"))  # fmt: skip
    cmap, (session,) = convert_log(log)
    assert cmap.name == "ur_rtde_headerless" and session.stats["sensing"] == "stock_reduced"
    assert session.stats["rows"] == len(t)  # the first line is data, not a header
    np.testing.assert_allclose(session.state[:, 0, 0], cols["actual_q_0"][::5], atol=1e-7)
    lines = log.read_text().splitlines()
    lines[7] = lines[7].replace(",", ",x", 1)
    log.write_text("\n".join(lines) + "\n")
    assert ingest_main([str(log), "--out", str(tmp_path / "bad")]) == 2
    assert "line 8: column 'actual_q_0': 'x" in capsys.readouterr().err


def test_the_short_headerless_layout_reads_without_the_targets(tmp_path, capsys):
    """The same logs' earlier layout: 19 numbers a row (time, positions, velocities, currents),
    read with the joint_states profile, and ingest says what it dropped and why."""
    log, cols, _ = _headerless(tmp_path / "ur-19_09_27-11_28_22.csv",
                               ("actual_q", "actual_qd", "actual_current"))  # fmt: skip
    cmap, (session,) = convert_log(log)
    assert cmap.name == "ur_rtde_headerless_short" and session.stats["sensing"] == "joint_states"
    np.testing.assert_allclose(session.state[:, 2, 2], cols["actual_current_2"][::5] * 9.65,
                               rtol=1e-6)  # fmt: skip
    assert ingest_main([str(log), "--out", str(tmp_path / "out")]) == 0
    said = capsys.readouterr().out
    assert "sensing profile joint_states" in said
    assert "effort_residual dropped (column 'target_current_0' missing)" in said
