"""The package's own entry points run as steps of a longer job (the research campaigns).

Why here: every campaign script runs ``python -m robohealth_mj.…`` steps one after another. A
step that fails has already said why in its one line; the job then stops with one more line
naming the step and its exit status, instead of a traceback of the subprocess call.
"""

from __future__ import annotations

import subprocess
import sys


def run_step(*args: str, quiet: bool = False) -> None:
    """``python -m ARGS`` in this interpreter, echoed first; ``quiet``: neither the echo nor the
    step's standard output (for a script whose output is a results table)."""
    if not quiet:
        print("+", " ".join(args), flush=True)
    done = subprocess.run(
        [sys.executable, "-m", *args], stdout=subprocess.DEVNULL if quiet else None, check=False
    )
    if done.returncode:
        print(
            f"step `python -m {args[0]}` exited with status {done.returncode}: stopped there",
            file=sys.stderr,
        )
        raise SystemExit(done.returncode)
