"""A page the toolkit wrote, opened offline in headless Chromium (Debian's, driven by Playwright),
and what a reader's browser did with it: console errors, page errors, failed and refused
requests, images, typeset formulas, live links and event handlers, and the first screen as PNG.

Playwright rather than Selenium: it reports console messages, page errors and failed requests as
events and can refuse every request a page makes (``context.route``), which WebDriver cannot
without the DevTools protocol; its Python package drives any Chromium through
``executable_path``, so Debian's package is enough (Playwright's own browser download is not
reachable from these machines).
"""
from __future__ import annotations

import re
import shutil
from dataclasses import dataclass, field
from pathlib import Path

#: Debian's Chromium (``./build.sh setup`` installs the package ``chromium``)
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
#: what a missing browser says: the browser tests fail with it, never skip
INSTALL_HINT = ("Chromium is not installed: the browser tests need Debian's chromium (run ./build.sh setup, or "
                "apt-get install chromium) and the pinned playwright package (pip install -c constraints.txt -e "
                "'.[test]')")
#: Chromium's flags on a closed network: no background connections, no sandbox (root in CI)
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--disable-default-apps"]
#: the marker a hostile string sets when its script runs: window.lcvPwned (not the page's title,
#: which holds the hostile text as text)
MARKER = "lcvPwned"
#: raw TeX left in visible text: $...$ with no space inside the delimiters (how a formula is written)
RAW_MATH = re.compile(r"\$\$?[^$\s][^$]*?\$\$?|\\\(|\\\[")


@dataclass
class PageReport:
    """What Chromium did with one page (see the module docstring)."""

    url: str
    console_errors: list = field(default_factory=list)
    page_errors: list = field(default_factory=list)
    failed_requests: list = field(default_factory=list)
    refused_requests: list = field(default_factory=list)
    images: int = 0
    broken_images: list = field(default_factory=list)
    math_typeset: int = 0
    math_errors: int = 0
    raw_math: list = field(default_factory=list)
    user_text_typeset: int = 0
    safe_extension: bool = False
    mathjax: bool = False
    live_links: list = field(default_factory=list)
    handlers: list = field(default_factory=list)
    marker: bool = False
    visible_text: str = ""
    #: the whole text a reader sees, the user's included
    full_text: str = ""
    screenshot: Path | None = None

    @property
    def clean(self) -> bool:
        """No console error, page error, failed or refused request, broken image or math error."""
        return not (self.console_errors or self.page_errors or self.failed_requests or self.refused_requests
                    or self.broken_images or self.math_errors)

    def problems(self) -> str:
        return "; ".join(f"{k}: {v}" for k, v in (
            ("console errors", self.console_errors), ("page errors", self.page_errors),
            ("failed requests", self.failed_requests), ("refused requests", self.refused_requests),
            ("broken images", self.broken_images), ("math errors", self.math_errors)) if v)


#: in the page: images, formulas, links, handlers, the marker, the visible text
_INSPECT = r"""() => {
  const imgs = Array.from(document.images);
  const broken = imgs.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => (i.src || '').slice(0, 80));
  const ignore = Array.from(document.querySelectorAll('.tex2jax_ignore'));
  const mathIn = el => el.querySelectorAll('.MathJax_CHTML, .MathJax, .mjx-chtml, script[type^="math/tex"]').length;
  const userTypeset = ignore.reduce((n, el) => n + mathIn(el), 0);
  const typeset = document.querySelectorAll('script[type^="math/tex"]').length;
  const errors = document.querySelectorAll('.MathJax_Error, merror, .mjx-merror').length
                 + (document.body.innerText.includes('Math Processing Error') ? 1 : 0);
  const live = Array.from(document.querySelectorAll('a[href], area[href], form[action], iframe[src], '
                                                    + 'object[data], embed[src], [xlink\\:href]'))
    .map(a => a.getAttribute('href') || a.getAttribute('action') || a.getAttribute('src')
              || a.getAttribute('data') || a.getAttribute('xlink:href') || '')
    .filter(h => /^\s*(javascript|data|vbscript):/i.test(h));
  const handlers = [];
  for (const el of document.querySelectorAll('*')) {
    for (const at of el.attributes) {
      if (/^on/i.test(at.name)) handlers.push(el.tagName.toLowerCase() + '[' + at.name + ']');
    }
  }
  // visible text outside MathJax's own output and outside the user's (ignored) text
  const clone = document.body.cloneNode(true);
  for (const el of clone.querySelectorAll('.tex2jax_ignore, script, style, .MathJax_CHTML, .MathJax, '
                                           + '.MathJax_Preview, .MJX_Assistive_MathML, mjx-container, svg')) {
    el.remove();
  }
  return {full: document.body.innerText, images: imgs.length, broken: broken, typeset: typeset, errors: errors, userTypeset: userTypeset,
          live: live, handlers: handlers, text: clone.innerText || clone.textContent,
          mathjax: typeof window.MathJax !== 'undefined',
          safe: typeof window.MathJax !== 'undefined' && !!(MathJax.Extension && MathJax.Extension.Safe),
          marker: !!window.__MARKER__};
}""".replace("__MARKER__", MARKER)

#: wait until MathJax (if the page has it) has finished typesetting, or 20 s
_MATHJAX_DONE = """() => new Promise(resolve => {
  if (typeof window.MathJax === 'undefined' || !MathJax.Hub) { resolve(false); return; }
  MathJax.Hub.Queue(() => resolve(true));
})"""


def launch(playwright):
    """Debian's Chromium, headless, offline flags; a clear failure when it is missing."""
    import pytest
    if not Path(CHROMIUM).exists():
        pytest.fail(INSTALL_HINT, pytrace=False)
    return playwright.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)


def browser_session():
    """A generator for a session fixture: Playwright started, Debian's Chromium launched, both
    closed at the end; a missing Playwright or Chromium fails with :data:`INSTALL_HINT`."""
    import pytest
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.fail(INSTALL_HINT, pytrace=False)
    with sync_playwright() as p:
        browser = launch(p)
        try:
            yield browser
        finally:
            browser.close()


def inspect(browser, index: Path, screenshot: Path | None = None, click_links: bool = False) -> PageReport:
    """Open ``index`` (a file) in a new context with every non-file request refused (and counted),
    wait for MathJax, and report (:class:`PageReport`); ``click_links``: click every link of the
    page, each in a fresh load, after which the marker must still be unset."""
    report = PageReport(Path(index).resolve().as_uri())
    context = browser.new_context(viewport={"width": 1200, "height": 900}, java_script_enabled=True)

    def route(r):
        if r.request.url.startswith("file:"):
            r.continue_()
        else:
            report.refused_requests.append(r.request.url)
            r.abort()
    context.route("**/*", route)
    page = context.new_page()
    page.on("console", lambda m: report.console_errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: report.page_errors.append(str(e)))
    page.on("requestfailed", lambda r: report.failed_requests.append(f"{r.url} ({r.failure})")
            if not r.url in report.refused_requests else None)
    page.on("dialog", lambda d: (setattr(report, "marker", True), d.dismiss()))
    page.goto(report.url, wait_until="load")
    page.evaluate(_MATHJAX_DONE)
    page.wait_for_timeout(100)
    found = page.evaluate(_INSPECT)
    report.images, report.broken_images = found["images"], found["broken"]
    report.math_typeset, report.math_errors = found["typeset"], found["errors"]
    report.user_text_typeset, report.live_links = found["userTypeset"], found["live"]
    report.handlers, report.visible_text, report.full_text = found["handlers"], found["text"], found["full"]
    report.mathjax, report.safe_extension = found["mathjax"], found["safe"]
    report.marker = report.marker or found["marker"]
    report.raw_math = RAW_MATH.findall(report.visible_text)
    if screenshot is not None:
        page.screenshot(path=str(screenshot))
        report.screenshot = screenshot
    if click_links:
        base = report.url.split("#", 1)[0]
        count = page.locator("a").count()
        for k in range(count):
            if page.url.split("#", 1)[0] != base:      # a link led away: back to the page
                page.goto(report.url, wait_until="load")
                page.evaluate(_MATHJAX_DONE)
            try:
                page.locator("a").nth(k).click(timeout=1000, no_wait_after=True)
            except Exception:                          # an invisible or detached link: nothing to click
                continue
            if page.url.split("#", 1)[0] == base:
                report.marker = report.marker or page.evaluate(_INSPECT)["marker"]
    context.close()
    return report
