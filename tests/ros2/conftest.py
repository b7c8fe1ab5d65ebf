"""The DDS tests run in one pytest process even when the suite is spread over workers
(``pytest -n 2 --dist loadgroup``, what ``make test`` runs): they pick DDS domains from a
per-process counter, and two processes' participants on one domain would hear each other."""

from __future__ import annotations

from pathlib import Path

import pytest

HERE = Path(__file__).parent


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    # a directory's conftest sees every collected item: mark only this directory's
    for item in items:
        if HERE in item.path.parents:
            item.add_marker(pytest.mark.xdist_group("dds"))
