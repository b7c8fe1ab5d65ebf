"""Keep a campaign's results when its machine goes: copy each finished run's records (summary
and evaluations, a few kB, no checkpoint) into a directory that is committed with the results.

A campaign's run directories live under ``outputs/`` with their checkpoints, which are large and
git-ignored. A session that loses its machine loses them, and with them every per-seed number
the report aggregates. The archive holds just what :func:`robohealth_mj.reporting.runs.collect`
reads, at the same relative paths, so the report is rebuilt from it and a later session's runs
join the earlier ones.
"""

from __future__ import annotations

from pathlib import Path

from robohealth_mj.common.atomic import atomic_write_text

SUMMARY = "train_summary.json"
BLOCKS = "blocks.tsv"


def finished_runs(root: Path) -> list[Path]:
    """Run directories under ``root`` with a summary and a held-out evaluation."""
    return sorted(
        p.parent for p in root.rglob(SUMMARY) if (p.parent / "eval_heldout.json").is_file()
    )


def archive_runs(root: Path, dest: Path) -> list[Path]:
    """Copy every finished run's ``train_summary.json`` and ``eval_*.json`` from ``root`` to the
    same relative path under ``dest`` (a rerun replaces its earlier record), and append
    ``root/blocks.tsv``'s lines that ``dest/blocks.tsv`` lacks. Returns the archived run
    directories under ``dest``."""
    if root.resolve() == dest.resolve():
        return finished_runs(dest)
    archived = []
    for run in finished_runs(root):
        target = dest / run.relative_to(root)
        target.mkdir(parents=True, exist_ok=True)
        for source in [run / SUMMARY, *sorted(run.glob("eval_*.json"))]:
            atomic_write_text(target / source.name, source.read_text())
        archived.append(target)
    if (root / BLOCKS).is_file():
        kept = (dest / BLOCKS).read_text().splitlines() if (dest / BLOCKS).is_file() else []
        new = [line for line in (root / BLOCKS).read_text().splitlines() if line not in kept]
        if new:
            dest.mkdir(parents=True, exist_ok=True)
            atomic_write_text(dest / BLOCKS, "".join(f"{line}\n" for line in kept + new))
    return archived
