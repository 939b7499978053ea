#!/usr/bin/env python3
"""Screenshots of `frog-bt report`'s page over a small seeded season (docs/report-*.png).

    .venv/bin/python scripts/report_screenshot.py [-o docs] [--corpus DIR] [--keep DIR]

Records a season with scripts/corpus_run.py (2 days of 10 tours, one tour of each help
event: a dock answered by hand, an operator's home and skip, an alert acknowledged, a
restart; corpus_run's default fast timings), or reads the recordings in ``--corpus``,
writes the report and takes the whole page with Debian's headless Chromium (chromium,
chromium-driver) at 1400 and 1024 px wide: ``report-1400.png``, ``report-1024.png``.
The window is made as tall as the page before each shot, so the shot is the whole page.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

from frog_bt.cli import main as frog_bt

sys.path.insert(0, str(Path(__file__).resolve().parent))
from console_screenshot import browser  # headless Chromium, as for the console
from corpus_run import make

WIDTHS = (1400, 1024)
TALL = "return Math.max(document.body.scrollHeight, document.documentElement.scrollHeight)"
DAYS, PER_DAY, SEED, HELP_EACH = 2, 10, 1, 1


def shoot(page: Path, out: Path) -> list[Path]:
    """The whole page at each width: the window as tall as the page, then a shot."""
    written = []
    driver = browser()
    try:
        driver.get(page.resolve().as_uri())
        wait = WebDriverWait(driver, 30, poll_frequency=0.1)
        wait.until(lambda d: d.find_element(By.ID, "shown").text.endswith(" tours"))
        for width in WIDTHS:
            driver.set_window_size(width, 900)
            wait.until(lambda d, w=width: d.execute_script("return window.innerWidth") == w)
            chrome = driver.execute_script("return window.outerHeight - window.innerHeight")
            driver.set_window_size(width, driver.execute_script(TALL) + chrome)
            wait.until(
                lambda d: d.execute_script("return window.innerHeight") >= d.execute_script(TALL)
            )
            scroll = driver.execute_script("return document.documentElement.scrollWidth")
            if scroll > width:
                print(f"warning: the page scrolls sideways at {width} px ({scroll} px wide)")
            path = out / f"report-{width}.png"
            path.write_bytes(driver.get_screenshot_as_png())
            written.append(path)
    finally:
        driver.quit()
    return written


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--out", type=Path, default=Path("docs"), help="folder (default: docs)")
    p.add_argument("--corpus", type=Path, help="recordings to report (default: record a season)")
    p.add_argument("--keep", type=Path, help="record the season here and keep it")
    p.add_argument("--jobs", type=int, default=2, help="tours recorded at once (processes)")
    a = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="frog-report-") as tmp:
        corpus = a.corpus
        if corpus is None:
            corpus = a.keep or Path(tmp) / "season"
            make(corpus, DAYS, PER_DAY, SEED, a.jobs, progress=True, help_each=HELP_EACH)
        html = Path(tmp) / "report.html"
        if frog_bt(["report", str(corpus), "-o", str(html), "--quiet"]) != 0:
            sys.exit("frog-bt report failed")
        for path in shoot(html, a.out):
            print(f"wrote {path}")


if __name__ == "__main__":
    main()
