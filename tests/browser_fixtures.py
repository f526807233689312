"""Fixtures for tests that drive a real browser: Debian's Chromium through Playwright.

Registered for the whole suite by ``tests/conftest.py``:

* ``browser`` — one headless Chromium for the test session (starting one costs
  about a second); Playwright's ``Browser``.
* ``page`` — a fresh page in its own context for one test, closed after it.
* ``js_file`` — ``js_file("mermaid/dist/mermaid.min.js")``: the path of a file of
  the tests' JavaScript packages (``tests/js``, installed by ``scripts/setup.sh``
  with ``npm ci``), to load into a page with ``page.add_script_tag(path=...)``.

Playwright does not download a browser here: it starts the Chromium of the
machine (``/usr/bin/chromium``, Debian's package, installed by
``scripts/setup.sh``; another one with ``TTT_SM_CHROMIUM=/path``).  When
Playwright, Chromium or the JavaScript packages are missing, the tests that need
them are skipped with a message that says what to install; with
``TTT_SM_REQUIRE_BROWSER=1`` (as ``.ci/run`` sets it) they fail instead, so CI
cannot pass without having run them.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import pytest

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Page

#: The tests' JavaScript packages (package.json, package-lock.json, node_modules/).
JS_DIR = Path(__file__).resolve().parent / "js"
DEFAULT_CHROMIUM = "/usr/bin/chromium"
#: Headless Chromium as root in a sandboxed machine with no network but loopback:
#: no sandbox of its own, no GPU, and none of its background connections, which the
#: closed network would refuse many at a time.
CHROMIUM_FLAGS = (
    "--no-sandbox",
    "--disable-gpu",
    "--disable-dev-shm-usage",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--no-first-run",
)


def browser_required() -> bool:
    """Whether a missing browser part fails the test instead of skipping it."""
    return os.environ.get("TTT_SM_REQUIRE_BROWSER", "") == "1"


def missing(what: str) -> NoReturn:
    """Skip the test because ``what`` is missing, or fail it when a browser is required."""
    if browser_required():
        pytest.fail(f"{what} (TTT_SM_REQUIRE_BROWSER=1: browser tests must run here)", pytrace=False)
    pytest.skip(what)


def chromium_executable() -> str:
    """The Chromium to start: ``TTT_SM_CHROMIUM``, else Debian's, else ``chromium`` on PATH."""
    wanted = os.environ.get("TTT_SM_CHROMIUM")
    if wanted:
        if not os.access(wanted, os.X_OK):
            missing(f"TTT_SM_CHROMIUM={wanted} is not an executable file")
        return wanted
    if os.access(DEFAULT_CHROMIUM, os.X_OK):
        return DEFAULT_CHROMIUM
    found = shutil.which("chromium")
    if found is None:
        missing(f"Chromium not found ({DEFAULT_CHROMIUM}): run `sh scripts/setup.sh`,"
                " which installs Debian's chromium, or set TTT_SM_CHROMIUM")
    return found


@pytest.fixture(scope="session")
def browser() -> Iterator[Browser]:
    """One headless Chromium for the whole session."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        missing("Playwright is not installed: `pip install -e '.[test]'` (or `make setup`)")
    executable = chromium_executable()
    playwright = sync_playwright().start()
    try:
        chromium = playwright.chromium.launch(executable_path=executable, args=list(CHROMIUM_FLAGS))
    except Exception:
        playwright.stop()
        raise
    try:
        yield chromium
    finally:
        chromium.close()
        playwright.stop()


@pytest.fixture
def page(browser: Browser) -> Iterator[Page]:
    """A fresh page, in a context of its own, for one test."""
    context = browser.new_context()
    try:
        yield context.new_page()
    finally:
        context.close()


@pytest.fixture(scope="session")
def js_file() -> Callable[[str], Path]:
    """``js_file(path)``: a file under ``tests/js/node_modules``, or skip (fail) if not installed."""

    def find(relative: str) -> Path:
        path = JS_DIR / "node_modules" / relative
        if not path.is_file():
            missing(f"{path.relative_to(JS_DIR.parent.parent)} is not installed: run `sh scripts/setup.sh`"
                    " (npm ci in tests/js; needs npm)")
        return path

    return find
