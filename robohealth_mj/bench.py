"""``python -m robohealth_mj.bench``: throughput benchmarks (not tests).

The page (``--help`` prints it), the parser and each benchmark's printing live in
:mod:`robohealth_mj.benchmarks.cli`.
"""

from __future__ import annotations

from robohealth_mj.benchmarks.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    main()
