"""The pages in a real browser: headless Chromium with the network off.

A worked-example page and three documentation pages are loaded from files; the test waits
for MathJax to typeset, then checks that no raw TeX is left in the rendered text, that the
console shows no error, that nothing was fetched from the network, and (on the worked-example
page) that moving a slider changes the plotted curve. Screenshots are saved as artifacts:
in $LAPLACE_SPRINGS_ARTIFACTS (``.ci/run`` sets it) or the test's temporary folder.

Needs Debian's ``chromium`` (``.ci/run`` installs it when missing) and the ``playwright``
Python package, which drives the installed browser (``executable_path``; no browser is
downloaded). Without either, the tests are skipped and say why.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

import laplace_springs as ls
from tests._docs_build import built_docs

playwright = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (pip install playwright)")
pytest.importorskip("mathjax", reason="the pages need the packaged MathJax (the pages extra)")
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="no chromium on this machine (.ci/run installs "
                                                         "Debian's chromium package)")

#: Chromium as the issue asks: headless, no sandbox (root in CI), no GPU, no background traffic,
#: a fresh profile (playwright gives each launch its own), and no name resolution at all.
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run",
         "--host-resolver-rules=MAP * ~NOTFOUND"]
#: What typeset math never leaves in the text a reader sees.
RAW_TEX = ("\\(", "\\)", "\\[", "\\]", "$$", "\\begin{", "\\frac", "\\lambda")


def _artifacts(tmp_path: Path) -> Path:
    folder = Path(os.environ.get("LAPLACE_SPRINGS_ARTIFACTS") or tmp_path) / "browser"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


@pytest.fixture(scope="module")
def browser():
    with playwright.sync_playwright() as driver:
        launched = driver.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        yield launched
        launched.close()


class Visit:
    """One page opened offline: its console errors and any request beyond file://."""

    def __init__(self, browser, url: str) -> None:
        self.page = browser.new_page(viewport={"width": 1100, "height": 900})
        self.errors: list[str] = []
        self.network: list[str] = []
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.route("**/*", self._route)
        self.page.goto(url)

    def _route(self, route) -> None:
        url = route.request.url
        if url.startswith(("file:", "data:", "blob:")):
            route.continue_()
        else:
            self.network.append(url)
            route.abort()

    def wait_for_math(self) -> None:
        self.page.wait_for_function("window.MathJax && MathJax.startup && MathJax.startup.promise",
                                    timeout=60_000)
        self.page.evaluate("MathJax.startup.promise.then(() => true)")

    def check(self, name: str, folder: Path) -> str:
        text = self.page.evaluate("document.body.innerText")
        self.page.screenshot(path=str(folder / f"{name}.png"), full_page=True)
        assert self.page.locator("mjx-container").count() > 0, f"{name}: nothing typeset"
        left = [d for d in RAW_TEX if d in text]
        assert not left, f"{name}: raw TeX left in the rendered text: {left}"
        assert not self.errors, f"{name}: console errors {self.errors}"
        assert not self.network, f"{name}: tried the network: {self.network}"
        return text


def test_worked_example_page_offline(browser, tmp_path):
    folder = _artifacts(tmp_path)
    page_file = ls.worked_example(ls.load_scene("three-dashpots")).save_html(tmp_path / "three-dashpots.html")
    visit = Visit(browser, page_file.as_uri())
    visit.page.wait_for_function("document.body.dataset.typeset === 'done'", timeout=60_000)
    text = visit.check("worked-example", folder)
    assert "Example 5" in text and "Turn the knobs" in text
    curve, plot = visit.page.locator("#ls-curve-0"), visit.page.locator("#ls-plot")
    before, set_before = curve.get_attribute("points"), plot.get_attribute("data-set")
    assert before and len(before.split()) == 121
    visit.page.locator("#ls-knob-0").fill("0")  # k1 to the low end of its range
    after, set_after = curve.get_attribute("points"), plot.get_attribute("data-set")
    assert after != before, "moving a slider did not change the plotted data"
    assert (int(set_before), int(set_after)) == (3 * 49 + 3 * 7 + 3, 3 * 7 + 3)  # 7 values per knob
    assert visit.page.locator("#ls-knob-value-0").inner_text() == "100"  # k1 = 400 / 4
    visit.page.screenshot(path=str(folder / "worked-example-slider.png"))
    visit.page.close()


@pytest.mark.parametrize("page", ["algorithm.html", "guide/resolvent.html",
                                  "_notebooks/02_example2_resolvent.html"])
def test_documentation_pages_offline(browser, page, tmp_path):
    pytest.importorskip("sphinx")
    pytest.importorskip("myst_nb")
    pytest.importorskip("nbclient")
    html, _, output = built_docs()  # test_docs fails on a warning; here the pages must exist
    assert (html / page).exists(), output
    visit = Visit(browser, (html / page).as_uri())
    visit.wait_for_math()
    visit.check(page.replace("/", "-").removesuffix(".html"), _artifacts(tmp_path))
    visit.page.close()
