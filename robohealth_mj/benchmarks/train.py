"""Training benchmark: windows/s per variant on real windows (data loading timed apart)."""

from __future__ import annotations

import time

import numpy as np

from robohealth_mj.benchmarks.common import fresh_variant, matmul_rate


def bench_train(
    data: list[str], variants: list[str], window: int, steps: int, batch: int
) -> list[dict]:
    """Training throughput per variant on real windows; data loading timed separately."""
    import torch
    from torch.utils.flop_counter import FlopCounterMode

    from robohealth_mj.common.config import compose_config
    from robohealth_mj.data.arrays import expand_paths, load_recordings
    from robohealth_mj.data.windows import make_windows, normalisation
    from robohealth_mj.learn.data import WindowTensors
    from robohealth_mj.learn.loss import loss_from_config

    t0 = time.perf_counter()
    rec = load_recordings(expand_paths(data))
    load_s = time.perf_counter() - t0
    windows = make_windows(rec, window)
    mean, std = normalisation(rec.x, windows)
    tensors = WindowTensors(rec.x, rec, mean, std, torch.device("cpu"))
    peak = matmul_rate()
    loss_fn = loss_from_config(compose_config("train").trainer)
    print(
        f"data: {len(rec)} samples, {len(windows)} windows; loading from the binary cache "
        f"{load_s:.2f} s; matmul rate {peak / 1e9:.0f} GFLOP/s; batch {batch}, W={window}"
    )
    rows = []
    rng = np.random.default_rng(0)
    for name in variants:
        torch.manual_seed(0)
        model = fresh_variant(name, window)
        opt = torch.optim.AdamW(model.parameters(), lr=1e-3)

        def step(b, model=model, opt=opt):
            loss, _ = loss_fn(model(b.x), b)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()

        first = tensors.batch(windows, rng.integers(0, len(windows), batch))
        with FlopCounterMode(display=False) as counter:
            step(first)
        flops_per_window = counter.get_total_flops() / batch
        for _ in range(3):
            step(first)
        gather = compute = 0.0
        for _ in range(steps):
            t = time.perf_counter()
            b = tensors.batch(windows, rng.integers(0, len(windows), batch))
            gather += time.perf_counter() - t
            t = time.perf_counter()
            step(b)
            compute += time.perf_counter() - t
        total = gather + compute
        rate = steps * batch / total
        row = {
            "variant": name,
            "windows_per_s": rate,
            "data_share": gather / total,
            "flops_per_window": flops_per_window,
            "flop_fraction": rate * flops_per_window / peak,
        }
        rows.append(row)
        print(
            f"{name:<20} {rate:>8,.0f} windows/s  data {row['data_share']:6.1%}  "
            f"{flops_per_window / 1e6:6.1f} MFLOP/window  {row['flop_fraction']:6.1%} of "
            f"matmul rate",
            flush=True,
        )
    return rows


def bench_headline(overrides: list[str]) -> dict:
    """The headline run end to end (data loading, training, selection, evaluation), as
    ``python -m robohealth_mj.train`` runs it: wall time, time to the best checkpoint, windows/s."""
    import tempfile
    from pathlib import Path

    from robohealth_mj.common.config import compose_config
    from robohealth_mj.learn.run import train_and_evaluate as run

    cfg = compose_config("train", ["trainer.progress=false", "skip_done=false", *overrides])
    with tempfile.TemporaryDirectory() as tmp:
        started = time.perf_counter()
        results = run(cfg, Path(tmp))
        wall = time.perf_counter() - started
    summary = results["train"]
    epochs = summary["epochs"]
    per_epoch = summary["windows"]["train"]
    if cfg.trainer.max_windows_per_epoch:
        per_epoch = min(per_epoch, int(cfg.trainer.max_windows_per_epoch))
    row = {
        "variant": summary["variant"],
        "window": summary["window"],
        "wall_seconds": wall,
        "seconds_to_best": summary["seconds_to_best"],
        "setup_seconds": summary["wall_seconds"] - summary["train_seconds"],
        "best_epoch": summary["best_epoch"],
        "epochs_run": epochs,
        "train_windows_per_s": epochs * per_epoch / summary["train_seconds"],
        "heldout": {
            k: results["heldout"]["metrics"][k] for k in ("accuracy", "localisation_accuracy")
        },
    }
    print(
        f"{row['variant']} W={row['window']}: best checkpoint after "
        f"{row['seconds_to_best'] + row['setup_seconds']:.0f} s (data {row['setup_seconds']:.0f}"
        f" s + training {row['seconds_to_best']:.0f} s, epoch {row['best_epoch']}/"
        f"{epochs}); whole command {wall:.0f} s; {row['train_windows_per_s']:,.0f} windows/s "
        f"incl. validation; held-out accuracy {row['heldout']['accuracy']:.3f}, localisation "
        f"{row['heldout']['localisation_accuracy']:.3f}",
        flush=True,
    )
    return row
