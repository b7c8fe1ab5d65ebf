"""``python -m robohealth_mj.bag``: recordings as ROS 2 bags (rosbag2, MCAP storage).

    python -m robohealth_mj.bag write SESSION [--out DIR]     # graphs.jsonl or a session dir
    python -m robohealth_mj.bag info BAG
    python -m robohealth_mj.bag plot BAG --out timeline.png   # truth and diagnosis, one timeline

``write`` converts a recording to a bag directory that ``ros2 bag info`` and Foxglove open
without plugins (standard messages only; topics in ``conf/bag.yaml``; the session manifest in the
bag's metadata). Every command that reads recordings (``dataset``, ``train``, ``evaluate``,
``monitor source=replay``) also takes such a bag directory.
"""

from __future__ import annotations

import argparse
import itertools
import json
from collections import Counter
from pathlib import Path

from robohealth_mj.common.errors import InputError, exit_status


def _write(args: argparse.Namespace) -> int:
    from robohealth_mj.bags.writer import write_bag
    from robohealth_mj.data.arrays import resolve_recordings
    from robohealth_mj.data.read import read_samples

    (source,) = resolve_recordings([args.session])
    out = Path(args.out) if args.out else source.parent / "bag"
    manifest_path = source.parent / "manifest.json"
    manifest = json.loads(manifest_path.read_text()) if manifest_path.is_file() else None
    samples = read_samples(source)
    first = next(samples, None)
    if first is None:
        raise InputError(f"{source}: no samples (an empty recording)")
    count = write_bag(itertools.chain([first], samples), out, manifest)
    print(f"wrote {count} samples from {source} -> {out}")
    return 0


def _info(args: argparse.Namespace) -> int:
    from rosbags.rosbag2 import Reader

    from robohealth_mj.bags import is_bag
    from robohealth_mj.bags.reader import bag_manifest

    if not is_bag(args.bag):
        raise FileNotFoundError(f"{args.bag}: not a rosbag2 directory (no metadata.yaml)")
    with Reader(args.bag) as reader:
        counts = Counter({c.topic: c.msgcount for c in reader.connections})
        types = {c.topic: c.msgtype for c in reader.connections}
        print(f"{args.bag}: {reader.message_count} messages, {reader.duration / 1e9:.2f} s")
        for topic in sorted(counts):
            print(f"  {topic:<36} {types[topic]:<38} {counts[topic]}")
    manifest = bag_manifest(args.bag)
    if manifest:
        seed = manifest.get("seed", manifest.get("config", {}).get("seed"))
        print(f"  manifest: run {manifest.get('recording_run_id')}, seed {seed}")
    return 0


def _plot(args: argparse.Namespace) -> int:
    from robohealth_mj.bags.figure import plot_timeline

    print(f"timeline -> {plot_timeline(args.bag, args.out)}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.bag",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="command", required=True)
    w = sub.add_parser("write", help="a recording -> a rosbag2 (MCAP) directory")
    w.add_argument("session", help="graphs.jsonl or a session directory")
    w.add_argument("--out", help="bag directory (default: bag/ beside the recording)")
    w.set_defaults(run=_write)
    p = sub.add_parser("plot", help="truth and diagnosis on one timeline (PNG)")
    p.add_argument("bag")
    p.add_argument("--out", required=True)
    p.set_defaults(run=_plot)
    i = sub.add_parser("info", help="topics, types and counts of a bag")
    i.add_argument("bag")
    i.set_defaults(run=_info)
    args = parser.parse_args(argv)
    return exit_status("bag", lambda: args.run(args), OSError, ValueError)
