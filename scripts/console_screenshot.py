#!/usr/bin/env python3
"""A screenshot of the operator's console during a simulated tour (docs/console.png).

    .venv/bin/python scripts/console_screenshot.py [-o docs/console.png]

Runs the default scenario at 20x with the console on a free loopback port, lets the
battery sag below the alert level at POI2 (so the banner shows), and takes the page with
Debian's headless Chromium (chromium, chromium-driver).
"""

from __future__ import annotations

import argparse
import asyncio
import shutil
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

from frog_bt.commands.console_options import ConsoleSettings, start_people
from frog_bt.config import load_site
from frog_bt.rehearsal import Rehearsal
from frog_bt.sim import scenario_from


def shoot(url: str, out: Path) -> None:
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "chromium"
    for arg in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--window-size=1280,1500",
        "--hide-scrollbars",
        "--no-proxy-server",
    ):
        options.add_argument(arg)
    driver = webdriver.Chrome(
        service=Service(shutil.which("chromedriver") or "chromedriver"), options=options
    )
    try:
        driver.get(url)
        wait = WebDriverWait(driver, 60, poll_frequency=0.1)
        wait.until(lambda d: d.find_element(By.ID, "stop").text.startswith("POI2"))
        wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, ".alert"))
        wait.until(lambda d: "b" in d.find_element(By.ID, "path").text)
        driver.save_screenshot(str(out))
    finally:
        driver.quit()


async def main(out: Path) -> None:
    site = load_site()
    rehearsal = Rehearsal(scenario_from("default", {"speed": 20.0}), site=site)
    async with rehearsal:
        people = await start_people(
            rehearsal.executive, ConsoleSettings("127.0.0.1", 0, "screenshot-token"), []
        )
        try:
            await rehearsal.sim.wait_for(
                lambda r: r.channel == "start_poi" and r.payload.get("poi") == "POI2", 120
            )
            rehearsal.sim.world.battery.percentage = 23.0
            assert people.console is not None
            await asyncio.to_thread(shoot, f"http://127.0.0.1:{people.console.bound_port}/", out)
        finally:
            rehearsal.executive.stop("screenshot taken")
            await people.close()
    print(f"wrote {out}")


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--out", type=Path, default=Path("docs/console.png"))
    asyncio.run(main(p.parse_args().out))
