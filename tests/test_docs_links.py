"""Every relative link of README.md and docs/*.md names a file that exists (a moved or renamed page breaks it)."""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"\]\(([^)\s#]+)(?:#[^)]*)?\)")  # [text](target) or [text](target#anchor)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_relative_links_name_existing_files(page):
    targets = [t for t in LINK.findall(page.read_text()) if "://" not in t and not t.startswith("mailto:")]
    assert [t for t in targets if not (page.parent / t).exists()] == []


def test_the_link_pattern_sees_a_missing_page():
    assert LINK.findall("see [tubes](docs/tubes.md#the-checks) and [x](https://a.b/c)") == ["docs/tubes.md",
                                                                                         "https://a.b/c"]
