"""``python -m robohealth_mj.corpus``: record the thesis's dataset roles in one command (§2.6.1).

- ``train``: sessions varied in seed, speed/payload grid and length (merged for training);
- ``heldout``: one session with its own seed (the cited test numbers);
- ``probe_payload_high``: the same fault mix at a payload outside the training range;
- any further role the corpus config names (``seed`` or ``seeds``, grid, length, overrides),
  e.g. ``probe_unseen_arms``: sessions each on its own drawn arm (``arm=varied``), and
  ``healthy_unseen_arms``: ten healthy minutes of each of those arms, to commission on.

Sessions run in parallel (one process per core by default). A finished session (manifest
``complete``) is skipped, so an interrupted corpus resumes where it stopped.

    python -m robohealth_mj.corpus                      # standard corpus
    python -m robohealth_mj.corpus corpus=quick         # small corpus for the main job and tests
    python -m robohealth_mj.corpus corpus=quick fault_model=hybrid   # + the thesis's signatures
    python -m robohealth_mj.corpus 'record_overrides=["faults.ramp_s=1.0"]'   # any record override

A list element that holds ``=`` must be quoted for Hydra's grammar, as above. A session on disk is
reused only when its manifest is complete, of this schema version and of the same run id (the
same config), so changing the fault model or any override re-records it.
"""

from __future__ import annotations

import os
from pathlib import Path

from hydra.utils import instantiate
from omegaconf import DictConfig

from robohealth_mj.common.config import run_tool
from robohealth_mj.common.errors import one_line_errors

with one_line_errors("corpus"):  # a missing extra is one line, not a traceback
    from robohealth_mj.recording.corpus import CORPUS_INDEX, build_corpus


def main(argv: list[str] | None = None) -> None:
    run_tool("corpus", run, argv)


def run(cfg: DictConfig) -> None:
    out_dir = Path(cfg.out_dir)
    jobs = cfg.jobs or os.cpu_count() or 1
    extra = [f"faults.fault_model={cfg.fault_model}", *cfg.record_overrides]
    with one_line_errors("corpus"):
        # sessions (build_corpus, also for a corpus config that names no builder) or lives
        build = instantiate(cfg.corpus.builder) if "builder" in cfg.corpus else build_corpus
        index = build(cfg.corpus, out_dir, jobs, extra, cfg.progress)
    unit = "life" if index.get("kind") == "lives" else "session"
    for role, entries in index["roles"].items():
        total = sum(s["samples"] for s in entries)
        print(f"{role:<20} {len(entries):>3} {unit}(s) {total:>9} samples")
    print(f"corpus index: {out_dir / CORPUS_INDEX}")


if __name__ == "__main__":
    main()
