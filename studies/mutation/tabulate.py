"""Per-module mutant counts from ``mutmut results --all true`` (read on standard input).

    .venv/bin/mutmut results --all true | python studies/mutation/tabulate.py [--sample 4]

``--sample K`` counts only the mutants whose number is a multiple of K (the before/after
comparison ran the old tests on that sample).
"""

from __future__ import annotations

import argparse
import re
import sys
from collections import Counter, defaultdict

MODULES = ("learn.metrics", "runtime.runtime", "runtime.alarms", "runtime.fleet",
           "bags.writer", "data.graphs")  # fmt: skip
STATES = ("killed", "survived", "no tests", "timeout", "suspicious", "not checked")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sample", type=int, default=1)
    args = parser.parse_args()
    counts: dict[str, Counter] = defaultdict(Counter)
    for line in sys.stdin:
        m = re.match(r"\s*robohealth_mj\.(\w+\.\w+)\..*__mutmut_(\d+): (.+)$", line.rstrip())
        if m and int(m.group(2)) % args.sample == 0:
            counts[m.group(1)][m.group(3)] += 1
    print("| module | mutants | killed | survived | no tests | timeout | not checked |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    total: Counter = Counter()
    for module in MODULES:
        c = counts[module]
        total.update(c)
        print(f"| `{module}` | {sum(c.values())} | {c['killed']} | {c['survived']} | "
              f"{c['no tests']} | {c['timeout']} | {c['not checked']} |")  # fmt: skip
    print(f"| all | {sum(total.values())} | {total['killed']} | {total['survived']} | "
          f"{total['no tests']} | {total['timeout']} | {total['not checked']} |")  # fmt: skip


if __name__ == "__main__":
    main()
