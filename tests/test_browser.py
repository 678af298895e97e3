"""A real browser (Debian's chromium, driven by Playwright) over a study's report and the docs' main pages.

Each page is loaded from a local HTTP server at 1200 px and at 400 px wide and fails on horizontal overflow,
a console error (or an uncaught exception), an image that did not load, or a link within the site that does
not resolve (a missing file, or an anchor with no element in its page).  Links that leave the site are not fetched: the
machines running the tests have no network.  Screenshots go to ``ci/screenshots/`` (``SWARMNAV_SCREENSHOTS``
to put them elsewhere), kept as the CI job's artefacts.  Nothing is downloaded: Playwright drives the
installed ``/usr/bin/chromium`` (``.ci/run`` installs it with apt-get when it is missing).
"""

from __future__ import annotations

import functools
import http.server
import os
import re
import threading
from pathlib import Path
from urllib.parse import unquote, urldefrag, urljoin, urlparse

import pytest

CHROMIUM = Path("/usr/bin/chromium")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]
WIDTHS_PX = (1200, 400)
DOCS_PAGES = ("index.html", "getting-started/demo/", "tutorials/first-run/", "reference/cli/",
              "reference/log-channels/", "reference/api/", "papers/", "results/")
SHOT_MAX_PX = 2400  # screenshots: the page from its top, at most this tall (a long page costs seconds)
REPO = Path(__file__).resolve().parent.parent
SCREENSHOTS = Path(os.environ.get("SWARMNAV_SCREENSHOTS", REPO / "ci" / "screenshots"))

STUDY = """
name = "browser-check"
description = "Two planners on one scenario, planned only: a small report for the browser test."
scenarios = ["gwo-scenario-1"]
mode = "plan"
seeds = 3
[[planners]]
name = "optimal"
[[planners]]
name = "gwo"
params = { population = 10, iterations = 10, penalty_weight = 1000.0, penalty_margin_m = 0.02 }
[[claims]]
id = "optimal-shorter"
statement = "the exact optimum is shorter than GWO's plan"
source = "synthetic"
scenario = "gwo-scenario-1"
metric = "plan_length_m"
better = "lower"
planner = "optimal"
than = ["gwo"]
test = "rank_sum"
"""

# What the page measures once loaded: overflow beyond the viewport, images that did not load, and links.
MEASURE = """() => ({
  overflow_px: document.documentElement.scrollWidth - window.innerWidth,
  widest: document.documentElement.scrollWidth <= window.innerWidth ? [] : [...document.querySelectorAll('body *')]
           .filter(e => e.getBoundingClientRect().right > window.innerWidth + 1).slice(0, 3)
           .map(e => e.tagName + '.' + e.className),
  height_px: document.documentElement.scrollHeight,
  broken_images: [...document.images].filter(i => !i.complete || i.naturalWidth === 0).map(i => i.src),
  links: [...document.querySelectorAll('a[href]')].map(a => a.href),
})"""


def _serve(folder: Path):
    handler = functools.partial(_QuietHandler, directory=str(folder))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


@pytest.fixture(scope="module")
def browser():
    if not CHROMIUM.exists():
        pytest.skip("no browser: install Debian's chromium (apt-get install chromium; .ci/run does it)")
    sync_api = pytest.importorskip("playwright.sync_api")
    os.environ.setdefault("PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD", "1")
    with sync_api.sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=str(CHROMIUM), args=FLAGS, headless=True)
        yield chromium
        chromium.close()


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    from swarmnav.cli.main import main
    folder = tmp_path_factory.mktemp("study")
    (folder / "browser-check.toml").write_text(STUDY)
    assert main(["study", str(folder / "browser-check.toml"), "--out", str(folder / "out"), "--workers", "1",
                 "--json"]) == 0
    assert main(["report", str(folder / "out")]) == 0
    return folder / "out"


def _look(browser, root: Path, pages: tuple[str, ...], name: str) -> list[str]:
    """Load every page at each width; return the problems found (and save a screenshot of each)."""
    server = _serve(root)
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    problems: list[str] = []
    links: set[str] = set()
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    try:
        for width in WIDTHS_PX:
            context = browser.new_context(viewport={"width": width, "height": 900})
            for page_path in pages:
                page = context.new_page()
                errors: list[str] = []
                page.on("console", lambda m, errors=errors: errors.append(m.text) if m.type == "error" else None)
                page.on("pageerror", lambda e, errors=errors: errors.append(str(e)))
                page.on("response", lambda r, errors=errors: errors.append(f"HTTP {r.status} for {r.url}")
                        if r.status >= 400 else None)
                url = urljoin(base, page_path)
                response = page.goto(url, wait_until="load")
                where = f"{name}/{page_path} at {width} px"
                if response is None or response.status != 200:
                    problems.append(f"{where}: HTTP {response.status if response else 'no response'}")
                found = page.evaluate(MEASURE)
                if found["overflow_px"] > 0:
                    problems.append(f"{where}: {found['overflow_px']} px horizontal overflow ({found['widest']})")
                problems += [f"{where}: console error: {text}" for text in errors]
                problems += [f"{where}: broken image {src}" for src in found["broken_images"]]
                links |= {link for link in found["links"] if link.startswith(base)}
                shot = page_path.strip("/").replace("/", "-").replace(".html", "") or "index"
                page.screenshot(path=str(SCREENSHOTS / f"{name}-{shot}-{width}px.png"), full_page=True,
                                clip={"x": 0, "y": 0, "width": width, "height": min(found["height_px"], SHOT_MAX_PX)})
                page.close()
            context.close()
        problems += _broken_links(root, base, links)
    finally:
        server.shutdown()
    return problems


def _broken_links(root: Path, base: str, links: set[str]) -> list[str]:
    """Every link within the site names a file that is there, and an anchor an element of that page."""
    problems = []
    for link in sorted(links):
        target, anchor = urldefrag(link)
        path = root / unquote(urlparse(target).path).lstrip("/")
        if path.is_dir():
            path = path / "index.html"
        if not path.is_file():
            problems.append(f"broken link {link}")
        elif anchor and path.suffix == ".html" and not re.search(rf"""id=["']?{re.escape(anchor)}["' >]""",
                                                                  path.read_text(errors="replace")):
            problems.append(f"broken anchor {link}")
    return problems


def test_the_docs_main_pages_look_right_at_both_widths(browser, docs_site):
    assert _look(browser, docs_site, DOCS_PAGES, "docs") == []


def test_a_study_report_looks_right_at_both_widths(browser, report):
    html = (report / "report.html").read_text()
    assert "optimal-shorter" in html  # the claim's verdict is on the page being looked at
    assert _look(browser, report, ("report.html",), "report") == []
