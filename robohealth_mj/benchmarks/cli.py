"""``python -m robohealth_mj.bench``: throughput benchmarks (not tests).

    python -m robohealth_mj.bench sim [--duration 60] [--arms ur5e,ur3e,ur10e,ur16e] [arm=ur10e]
    python -m robohealth_mj.bench models [--windows 16 32] [--variants anomaly_residual ...]
    python -m robohealth_mj.bench train [--data 'outputs/corpus/quick/train_*'] [--window 32]
    python -m robohealth_mj.bench train --headline [OVERRIDE ...]
    python -m robohealth_mj.bench infer [--data outputs/corpus/quick/heldout_seed900] [--window 32]
    python -m robohealth_mj.bench infer --model MODEL.onnx
    python -m robohealth_mj.bench streams [--model M] [--streams 1000] [--seconds 30]
    python -m robohealth_mj.bench streams --profile 1000 2000 [--shards 1]
    python -m robohealth_mj.bench streams --compare HEADLINE.onnx SMALL.onnx ...
    python -m robohealth_mj.bench soak [--model M] [--streams 1000] [--seconds 60]
    python -m robohealth_mj.bench ros2 --model M [--arms 10 25 50] [--seconds 20] [--monitors 1 2]
        [--graphs open secured]
    python -m robohealth_mj.bench contact [--streams 100 1000 4000]
    python -m robohealth_mj.bench mixed --model A.onnx B.onnx --data A_DATA B_DATA [--streams 500]

``sim`` measures, in one run, the raw ``mj_step`` rate of the scene and the recorder's throughput
(physics + control + sensor synthesis + JSONL writing), and reports their ratio. ``train
--headline`` runs the headline training (``anomaly_residual``, W = 32, standard corpus) end to end
and reports the time to its best checkpoint, data loading included. ``streams`` replays real
recordings on many interleaved 20 Hz streams through the fleet runtime: the largest stream count
whose per-tick p99 fits the 50 ms tick (search), then a paced run at ``--streams`` with its CPU
share, and the windowed path beside the incremental one. ``soak`` runs a fleet under bad input
(see ``robohealth_mj/benchmarks/soak.py``) and checks every flagged row and the memory. ``contact``
times the contact watch's update over streams that all hold a pose (its worst case). ``mixed``
runs two arms' models (a six- and a seven-joint arm) in one process against each alone.
"""

from __future__ import annotations

import argparse


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.bench",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="what", required=True)
    sim = sub.add_parser("sim", help="raw mj_step rate vs recorder throughput")
    sim.add_argument("--duration", type=float, default=60.0, help="simulated seconds to record")
    sim.add_argument(
        "--arms",
        default=None,
        help="comma-separated arms (ur3e,ur5e,ur10e,ur16e,ur20,ur30) measured back to back in this "
        "run, each recorder's throughput against the first arm's latest reading (repeat the pair, "
        "e.g. ur5e,ur30,ur5e,ur30, to bracket the machine's load)",
    )
    sim.add_argument("overrides", nargs="*", help="Hydra overrides for conf/record.yaml")
    models = sub.add_parser("models", help="parameters and batch-1 CPU latency per variant")
    models.add_argument("--windows", type=int, nargs="+", default=[16, 32])
    models.add_argument("--variants", nargs="+", default=None, help="default: every network")
    train = sub.add_parser("train", help="training throughput per variant, or the headline run")
    train.add_argument("--data", nargs="+", default=["outputs/corpus/quick/train_*"])
    train.add_argument("--variants", nargs="+", default=["mlp", "stgnn_fixed", "anomaly_residual"])
    train.add_argument("--window", type=int, default=32)
    train.add_argument("--steps", type=int, default=20)
    train.add_argument("--batch", type=int, default=128)
    train.add_argument(
        "--headline", action="store_true", help="time the headline training run to its best"
    )
    train.add_argument("overrides", nargs="*", help="Hydra overrides for --headline")
    infer = sub.add_parser("infer", help="deployment latency, throughput and stream capacity")
    infer.add_argument("--data", nargs="+", default=["outputs/corpus/quick/heldout_seed900"])
    infer.add_argument("--variants", nargs="+", default=None, help="default: every network")
    infer.add_argument("--window", type=int, default=32)
    infer.add_argument("--batch", type=int, default=256)
    infer.add_argument("--model", default=None, help="an exported model (instead of --variants)")
    headline = "studies/earlier_campaigns/results/headline_physics/anomaly_residual_w32_seed42.onnx"
    streams = sub.add_parser("streams", help="fleet load test: sustained 20 Hz streams")
    soak = sub.add_parser("soak", help="fleet under bad input: flags, tick budget, memory")
    ros2 = sub.add_parser("ros2", help="arms per monitor over DDS on loopback, end-to-end latency")
    contact = sub.add_parser("contact", help="the contact watch's cost per fleet tick")
    contact.add_argument("--streams", type=int, nargs="+", default=[100, 1000, 4000])
    mixed = sub.add_parser("mixed", help="a mixed fleet (two arm kinds) against each alone")
    mixed.add_argument("--model", nargs=2, required=True, help="two exported models")
    mixed.add_argument("--data", nargs=2, required=True, help="each model's arm's recordings")
    mixed.add_argument("--streams", type=int, default=500, help="streams of each arm kind")
    mixed.add_argument("--ticks", type=int, default=100, help="timed ticks per run")
    mixed.add_argument("--rounds", type=int, default=3, help="alternated rounds")
    ros2.add_argument("--model", required=True, help="an exported model.onnx or a ready one")
    ros2.add_argument("--data", default="outputs/corpus/quick/heldout_seed900")
    ros2.add_argument("--arms", type=int, nargs="+", default=[10, 25, 50])
    ros2.add_argument("--seconds", type=float, default=20.0)
    ros2.add_argument(
        "--layouts", nargs="+", default=["per_sensor", "aggregated"],
        choices=["per_sensor", "aggregated", "ur_driver"],
    )  # fmt: skip
    ros2.add_argument(
        "--monitors", type=int, nargs="+", default=[1],
        help="monitor processes sharing the arms (ros2.partition=k/n), one row per count",
    )  # fmt: skip
    ros2.add_argument(
        "--health-hz", type=float, default=20.0, help="each arm's /health_diagnosis rate"
    )
    ros2.add_argument(
        "--driver-hz", type=float, default=500.0,
        help="ur_driver layout: the controller's rate (joint and controller states per second)",
    )  # fmt: skip
    ros2.add_argument(
        "--graphs", nargs="+", default=["open"], choices=["open", "secured"],
        help="open and/or SROS2-secured graph (secured: a keystore made for the run; needs the "
        "binding of `make setup-sros2`), one row each, side by side",
    )  # fmt: skip
    ros2.add_argument(
        "--diagnose-wait-s", type=float, default=0.02,
        help="how long a completed sample waits for the other arms' (ros2.diagnose_wait_s)",
    )  # fmt: skip
    ros2.add_argument(
        "--kill", type=int, default=0, choices=[0, 1],
        help="1: a monitor group under kill and restart instead (--monitors N, --arms A: the "
        "first of each; aggregated layout): recovery, double diagnosis and loss per cycle",
    )  # fmt: skip
    ros2.add_argument("--cycles", type=int, default=10, help="--kill 1: kill/restart cycles")
    for p, seconds in ((streams, 30.0), (soak, 60.0)):
        p.add_argument("--model", default=headline)
        p.add_argument("--data", nargs="+", default=["outputs/corpus/standard/heldout_seed900"])
        p.add_argument("--streams", type=int, default=1000)
        p.add_argument("--seconds", type=float, default=seconds, help="paced run length")
        p.add_argument("--shards", type=int, default=2, help="threads the fleet step uses")
        p.add_argument("--chunk", type=int, default=256, help="streams per model call")
        p.add_argument(
            "--providers",
            type=lambda text: [name for name in text.split(",") if name],
            default=None,
            help="comma-separated ONNX Runtime execution providers, first preferred (e.g. "
            "CPUExecutionProvider); default: CUDA where onnxruntime-gpu finds a GPU, else CPU",
        )
    streams.add_argument("--no-search", action="store_true", help="skip the stream-count search")
    streams.add_argument(
        "--compare", nargs="+", default=None, metavar="MODEL",
        help="instead: MFLOP per stream-tick and sustained streams of each model (MODEL@k: "
        "run every k-th tick of a stream, monitor decide_every=k), with ratios to the first "
        "(the cost frontier)",
    )  # fmt: skip
    streams.add_argument("--limit", type=int, default=8192, help="largest stream count searched")
    streams.add_argument("--start", type=int, default=250, help="first stream count searched")
    streams.add_argument(
        "--decide-every", type=int, default=1,
        help="run the model on a stream every this many ticks (monitor decide_every)",
    )  # fmt: skip
    streams.add_argument(
        "--profile",
        type=int,
        nargs="+",
        default=None,
        metavar="STREAMS",
        help="instead of the search: where each tick's time goes at these stream counts",
    )
    streams.add_argument("--profile-ticks", type=int, default=100, help="ticks per profile")
    streams.add_argument(
        "--memory-horizon",
        type=float,
        default=10.0,
        help="evidence horizon (s) of the with/without-memory comparison",
    )
    streams.add_argument(
        "--memory-rounds",
        type=int,
        default=3,
        help="alternated rounds of the with/without-memory comparison (0: skip it)",
    )
    args = parser.parse_args(argv)
    if args.what == "mixed":
        from robohealth_mj.benchmarks.mixed import bench_mixed
        from robohealth_mj.common.errors import one_line_errors

        with one_line_errors("bench"):
            bench_mixed(args.model, args.data, args.streams, args.ticks, args.rounds)
    elif args.what == "contact":
        from robohealth_mj.benchmarks.contact import bench_contact

        bench_contact(args.streams)
    elif args.what == "ros2":
        from robohealth_mj.benchmarks.ros2 import bench_ros2
        from robohealth_mj.common.errors import one_line_errors

        with one_line_errors("bench"):
            if args.kill:
                from robohealth_mj.benchmarks.failover import bench_failover

                bench_failover(args.model, args.data, args.monitors[0], args.arms[0], args.cycles)
                return
            bench_ros2(args.model, args.data, args.arms, args.seconds, args.layouts,
                       args.monitors, args.health_hz, args.diagnose_wait_s,
                       args.graphs, args.driver_hz)  # fmt: skip
    elif args.what in ("streams", "soak"):
        from robohealth_mj.benchmarks.fleet import bench_fleet, bench_soak
        from robohealth_mj.common.errors import one_line_errors

        with one_line_errors("bench"):
            (bench_fleet if args.what == "streams" else bench_soak)(args)
    elif args.what == "infer" and args.model:
        from robohealth_mj.benchmarks.infer import bench_deployed

        bench_deployed(args.model, args.data, args.batch)
    elif args.what == "infer":
        from robohealth_mj.benchmarks.infer import bench_infer
        from robohealth_mj.models import NETWORK_VARIANTS

        bench_infer(args.data, args.variants or list(NETWORK_VARIANTS), args.window, args.batch)
    elif args.what == "train" and args.headline:
        from robohealth_mj.benchmarks.train import bench_headline

        bench_headline(args.overrides)
    elif args.what == "train":
        from robohealth_mj.benchmarks.train import bench_train

        bench_train(args.data, args.variants, args.window, args.steps, args.batch)
    elif args.what == "models":
        from robohealth_mj.benchmarks.models import bench_models
        from robohealth_mj.models import NETWORK_VARIANTS

        print("batch-1 latency on one CPU thread: median and p95 of 200 calls after 10 warm-ups")
        bench_models(args.windows, args.variants or list(NETWORK_VARIANTS))
    else:
        from robohealth_mj.benchmarks.sim import bench_sim

        if args.arms:
            rates = {}
            for arm in args.arms.split(","):
                r = bench_sim(args.duration, [*args.overrides, f"arm={arm}"])
                rates[arm] = r["recorder_sim_s_per_s"]
                first = next(iter(rates.values()))
                print(
                    f"{arm:<6} raw {r['raw_steps_per_s']:>8.0f} steps/s  recorder "
                    f"{r['recorder_sim_s_per_s']:>6.1f}x real time  "
                    f"{r['recorder_sim_s_per_s'] / first:>6.1%} of {next(iter(rates))}'s"
                )
            return
        r = bench_sim(args.duration, args.overrides)
        print(
            f"raw mj_step rate      {r['raw_steps_per_s']:>10.0f} steps/s "
            f"({r['raw_sim_s_per_s']:.1f} sim s per wall s)"
        )
        print(
            f"recorder throughput   {r['recorder_sim_s_per_s']:>10.1f} sim s per wall s "
            f"({r['recorder_sim_s_per_s']:.0f}x real time)"
        )
        print(f"recorder / raw        {r['ratio']:>10.1%}   (target >= 50%)")


if __name__ == "__main__":
    main()
