"""The documentation site builds with ``mkdocs build --strict`` (one build, into a temporary folder), has the
API reference from the docstrings, and has a page for every section the README moved into it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

pytest.importorskip("mkdocs")
pytest.importorskip("mkdocstrings")

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def site(docs_site) -> Path:
    return docs_site


def test_the_site_builds_strict_with_every_page_of_the_nav(site):
    nav_pages = re.findall(r":\s*([\w/.-]+\.md)\s*$", (REPO / "mkdocs.yml").read_text(), re.M)
    assert len(nav_pages) >= 20
    for page in nav_pages:
        built = site / (page[:-3] + "/index.html" if page != "index.md" else "index.html")
        assert built.is_file(), page
    on_disk = {str(p.relative_to(REPO / "docs")) for p in (REPO / "docs").rglob("*.md")}
    assert on_disk == set(nav_pages), "a page is missing from mkdocs.yml's nav, or the nav names a missing page"


def test_the_api_reference_is_generated_from_the_docstrings(site):
    html = (site / "reference" / "api" / "index.html").read_text()
    from swarmnav.log.writer import McapRecorder
    from swarmnav import RunOutcome
    for name in ("swarmnav.run", "swarmnav.results.RunOutcome", "swarmnav.planners.problem.Problem",
                 "swarmnav.log.writer.McapRecorder", "swarmnav.env.task.EnvOptions"):
        assert f'id="{name}"' in html, name
    # A sentence of a docstring reaches the page (text, not just headings).
    for docstring in (McapRecorder.__doc__, RunOutcome.__doc__):
        first = docstring.strip().splitlines()[0].strip().rstrip(".").replace("``", "")
        words = re.sub(r"[^\w ]", " ", first).split()[:4]
        assert all(word in html for word in words), first


def test_the_getting_started_picture_is_on_the_page_and_in_the_site(site):
    html = (site / "getting-started" / "demo" / "index.html").read_text()
    assert 'src="../../images/demo.png"' in html and (site / "images" / "demo.png").stat().st_size > 20_000


def _sections(markdown: str) -> dict[str, str]:
    """``## `` heading -> its text, outside code fences."""
    sections: dict[str, list[str]] = {}
    current, fence = None, False
    for line in markdown.splitlines():
        fence ^= line.startswith("```")
        if not fence and line.startswith("## "):
            current = line[3:].strip()
            sections[current] = []
        elif current is not None:
            sections[current].append(line)
    return {heading: "\n".join(lines) for heading, lines in sections.items()}


def test_every_readme_section_has_its_text_in_a_docs_page():
    """Nothing lost: the first lines of prose (or code) of every README section are in some docs page."""
    docs = "\n".join(p.read_text() for p in (REPO / "docs").rglob("*.md"))
    flat_docs = " ".join(docs.split())
    sections = _sections((REPO / "README.md").read_text())
    assert sections
    for heading, text in sections.items():
        lines = [line for line in text.splitlines() if line.strip()
                 and not line.lstrip().startswith(("<!--", "|", "![", "#", "- [", "[", "*The demo"))]
        if heading == "Documentation":
            continue  # the front page's links to the pages
        probe = " ".join(" ".join(lines[:2]).split())[:120]
        assert probe in flat_docs, f"README section {heading!r} is not in docs/ ({probe!r})"
