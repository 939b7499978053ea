"""Debian's Chromium, headless, driven by Selenium (chromium-driver): the one way the
browser tests start it, and their skip where it is not installed (never in CI, where
``.ci/run`` installs it)."""

from __future__ import annotations

import os
import shutil
from typing import TYPE_CHECKING

import pytest

if TYPE_CHECKING:
    from selenium import webdriver

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")


def require() -> None:
    """Skip the calling test module unless Chromium and its driver are installed (or CI
    is running, which must have them: there the missing browser fails the tests)."""
    if not (CHROMIUM and DRIVER) and os.environ.get("CI") != "true":
        pytest.skip(
            "Debian's chromium and chromium-driver are not installed "
            "(apt-get install chromium chromium-driver)",
            allow_module_level=True,
        )


def browser(width: int, height: int, *flags: str) -> webdriver.Chrome:
    """A headless Chromium with a window of ``width`` x ``height`` and ``flags`` more;
    offline (no proxy)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM or "chromium"
    for arg in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        f"--window-size={width},{height}",
        "--no-proxy-server",
        *flags,
    ):
        options.add_argument(arg)
    return webdriver.Chrome(service=Service(DRIVER or "chromedriver"), options=options)
