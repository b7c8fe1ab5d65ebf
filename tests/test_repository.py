"""The repository as a reader meets it: every relative link in its pages leads somewhere, and every
file the studies move named is where the move put it."""

import re
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
LINK = re.compile(r"\]\(([^)\s]+)\)")


def _tracked(pattern: str) -> list[Path]:
    out = subprocess.run(
        ["git", "ls-files", pattern], cwd=REPO, capture_output=True, text=True, check=False
    ).stdout.split()
    return [REPO / p for p in out]


PAGES = [p for p in _tracked("*.md") if "/results/runs/" not in str(p)]


def _broken_links(page: Path) -> list[str]:
    broken = []
    for target in LINK.findall(page.read_text()):
        path = target.split("#", 1)[0]
        if not path or re.match(r"^[a-z]+:", path) or path.startswith("/"):
            continue
        resolved = (page.parent / path).resolve()
        if not resolved.is_relative_to(REPO):
            continue  # ../shared/…: beside the repository, not in it
        if not resolved.exists():
            broken.append(target)
    return broken


@pytest.mark.skipif(not PAGES, reason="not a git checkout")
def test_every_relative_link_in_the_pages_resolves():
    broken = {str(p.relative_to(REPO)): b for p in PAGES if (b := _broken_links(p))}
    assert not broken, broken


def test_the_link_check_catches_a_missing_target(tmp_path):
    page = tmp_path / "page.md"
    (tmp_path / "there.md").write_text("x")
    page.write_text("[a](there.md) [b](gone.md#x) [c](https://example.org) [d](#top)")
    # resolve() relative to a page outside the repository is skipped; check inside it instead
    inside = REPO / "studies" / "_link_check_probe.md"
    inside.write_text(page.read_text())
    try:
        assert _broken_links(inside) == ["there.md", "gone.md#x"]
    finally:
        inside.unlink()


def test_every_moved_file_is_where_the_move_put_it():
    rows = (REPO / "studies" / "MOVED.tsv").read_text().splitlines()[1:]
    assert len(rows) > 700
    missing = [new for old, new in (r.split("\t") for r in rows) if not (REPO / new).exists()]
    assert not missing, missing[:10]
    assert not (REPO / "experiments").exists() and not (REPO / "results").exists()
