#!/usr/bin/env bash
# Mutation testing of the decision path (README "Tests"; results in README.md beside this file).
# mutmut 3.8.1; modules and test files: [tool.mutmut] in pyproject.toml. Run from the repo root.
set -euo pipefail
.venv/bin/pip install -q -e '.[mutation]'
export ROBOHEALTH_TEST_CACHE=${ROBOHEALTH_TEST_CACHE:-/tmp/robohealth_fixtures}

# Every mutant against today's tests (the whole run: about 2 hours on 2 cores). This page's run
# stopped the fleet module after the mutants below, then named them explicitly:
#   .venv/bin/mutmut run --max-children 2 NAME ...
.venv/bin/mutmut run --max-children 2
.venv/bin/mutmut results --all true | python studies/mutation/tabulate.py
# One mutant in four (the before/after comparison):
.venv/bin/mutmut results --all true | awk -F': ' '{print $1}' | sed 's/^ *//' \
  | awk -F'__mutmut_' '$2 % 4 == 0' > /tmp/sample.txt
.venv/bin/mutmut results --all true | python studies/mutation/tabulate.py --sample 4

# Before: the tests of commit 40376a8 on the same sample, in a worktree whose conftest's
# `deployed` and test_training's `tiny_corpus` read the same on-disk cache, and whose
# [tool.mutmut] lists only the test files that existed then:
#   git worktree add /tmp/before 40376a8 && cd /tmp/before   # (those two edits)
#   mutmut run --max-children 2 $(cat /tmp/sample.txt)
#   mutmut results --all true | python studies/mutation/tabulate.py --sample 4
