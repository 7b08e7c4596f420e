"""Helpers for tests, benchmarks and tools that drive goby-liaison's page in a real browser.

A headless Chromium (Debian's ``chromium`` and ``chromium-driver``) through selenium, with the flags that work
on machines without a display or a network, and a private profile directory removed on exit.
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

CHROMIUM_CANDIDATES = ("chromium", "chromium-browser", "google-chrome")
CHROMEDRIVER = "chromedriver"
PROFILE_PREFIX = "liaison-chromium-"  # the browser's profile directory (so its processes can be found)
CHROMIUM_FLAGS = (
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-dev-shm-usage", "--window-size=1400,900",
)


def chromium_paths() -> tuple[str | None, str | None]:
    """(browser, driver) executables found on PATH."""
    browser = next((found for name in CHROMIUM_CANDIDATES if (found := shutil.which(name))), None)
    return browser, shutil.which(CHROMEDRIVER)


def browser_skip_reason() -> str | None:
    """Why browser tests cannot run here, or None when they can."""
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install -e '.[test]')"
    browser, driver = chromium_paths()
    if browser is None or driver is None:
        return "chromium and chromium-driver are not installed (apt-get install chromium chromium-driver)"
    return None


@contextmanager
def chromium(window: tuple[int, int] = (1400, 900)) -> Iterator[Any]:
    """A headless Chromium WebDriver, quit (and its profile removed) on exit."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    browser, driver_path = chromium_paths()
    if browser is None or driver_path is None:
        raise RuntimeError(browser_skip_reason() or "no chromium")
    profile = Path(tempfile.mkdtemp(prefix=PROFILE_PREFIX))
    options = webdriver.ChromeOptions()
    options.binary_location = browser
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--window-size={window[0]},{window[1]}")
    options.add_argument(f"--user-data-dir={profile}")
    driver = webdriver.Chrome(service=Service(driver_path), options=options)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)
