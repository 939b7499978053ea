#!/usr/bin/env python3
"""Screenshots of the operator's console during a simulated tour (docs/console-*.png).

    .venv/bin/python scripts/console_screenshot.py [-o docs]

Runs the ``dock_fails`` scenario with the console on a free loopback port and takes the
whole page with Debian's headless Chromium (chromium, chromium-driver), on a phone
(390x844) and a tablet (1024x768), in Spanish and English:

* ``console-tour-{es,en}-{390,1024}.png``: at the Hunting Courtyard (POI2), the battery
  sagged below the alert level (so an alert shows);
* ``console-help-{es,en}-{390,1024}.png``: docking failed after all its attempts, the
  robot waits for a person.

The simulator runs slowly while a screenshot is taken (sim time) and fast in between.
"""

from __future__ import annotations

import argparse
import asyncio
import base64
import shutil
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

from frog_bt.commands.console_options import ConsoleSettings, start_people
from frog_bt.config import load_site
from frog_bt.model import keys
from frog_bt.rehearsal import Rehearsal
from frog_bt.sim import scenario_from

SIZES = ((390, 844), (1024, 768))
LANGUAGES = ("es", "en")
SLOW, FAST = 2.0, 50.0  # the simulator's speed while shooting, and in between


def browser() -> webdriver.Chrome:
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "chromium"
    for arg in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--hide-scrollbars",
        "--no-proxy-server",
        "--force-device-scale-factor=1",
    ):
        options.add_argument(arg)
    return webdriver.Chrome(
        service=Service(shutil.which("chromedriver") or "chromedriver"), options=options
    )


def shoot(driver: webdriver.Chrome, url: str, out: Path, name: str, ready: str) -> list[Path]:
    """The page at every size and in every language, once the element ``ready`` (an
    XPath) shows; the whole page, beyond the viewport."""
    written = []
    driver.get(url)
    wait = WebDriverWait(driver, 60, poll_frequency=0.1)
    for lang in LANGUAGES:
        Select(driver.find_element(By.ID, "lang")).select_by_value(lang)
        wait.until(
            lambda d, lang=lang: d.execute_script("return document.documentElement.lang") == lang
        )
        for width, height in SIZES:
            driver.execute_cdp_cmd(
                "Emulation.setDeviceMetricsOverride",
                {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": width < 600},
            )
            driver.execute_script("window.dispatchEvent(new Event('resize'))")
            wait.until(lambda d: d.find_elements(By.XPATH, ready))
            wait.until(lambda d: d.execute_script("return document.fonts.status") == "loaded")
            full = driver.execute_script("return document.documentElement.scrollHeight")
            shot = driver.execute_cdp_cmd(
                "Page.captureScreenshot",
                {
                    "captureBeyondViewport": True,
                    "clip": {"x": 0, "y": 0, "width": width, "height": full, "scale": 1},
                },
            )
            path = out / f"console-{name}-{lang}-{width}.png"
            path.write_bytes(base64.b64decode(shot["data"]))
            written.append(path)
    driver.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})
    return written


async def main(out: Path) -> None:
    site = load_site()
    rehearsal = Rehearsal(scenario_from("dock_fails", {"speed": FAST}), site=site, once=False)
    driver = await asyncio.to_thread(browser)
    written: list[Path] = []
    try:
        async with rehearsal:
            sim, exe = rehearsal.sim, rehearsal.executive
            people = await start_people(
                exe, ConsoleSettings("127.0.0.1", 0, "screenshot-token"), []
            )
            assert people.console is not None
            url = f"http://127.0.0.1:{people.console.bound_port}/"
            try:
                await sim.wait_for(
                    lambda r: r.channel == "start_poi" and r.payload.get("poi") == "POI2", 120
                )
                sim.world.battery.percentage = 23.0
                sim.speed = SLOW
                alert = "//*[@role='alert']"
                written += await asyncio.to_thread(shoot, driver, url, out, "tour", alert)
                sim.speed = FAST
                for _ in range(3000):  # at most 5 minutes
                    if exe.core.board.get(keys.HELP) is not None:
                        break
                    await asyncio.sleep(0.1)
                sim.speed = SLOW
                helped = "//section[@class='help' and not(@hidden)]"
                written += await asyncio.to_thread(shoot, driver, url, out, "help", helped)
            finally:
                exe.stop("screenshots taken")
                await people.close()
    finally:
        await asyncio.to_thread(driver.quit)
    for path in written:
        print(f"wrote {path}")


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--out", type=Path, default=Path("docs"), help="folder (default: docs)")
    asyncio.run(main(p.parse_args().out))
