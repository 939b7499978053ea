"""An attendant's walk-through of the console in Spanish, in a real browser (Debian's
Chromium, headless, driven by Selenium): every control is found by its visible words and
its role alone (XPath on text, no ids, no CSS selectors), as a person reading the phone
would. Three things, one browser:

* *Volver a la base*, confirmed: the tour ends (``operator``) and the robot docks;
* *Fuera de servicio*, confirmed, before the front end is ready: when it says
  ``frontend_idle``, no tour starts;
* a dock that fails (``dock_failures: 3``) asks for a person; someone puts the robot on
  its charger and taps *Hecho*: the robot goes on.

Sim time throughout: the simulator runs slowly while the browser acts (a bound, not a
pace) and fast once the page has answered. Skipped where Chromium is not installed,
except in CI (``CI=true``).
"""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from typing import Any

import chromium
import pytest
from console_tour import console_tour
from test_faults import is_

from frog_bt.model import keys

chromium.require()

from attendant import WAIT, answer, button, give_code, sees, tap_and_confirm  # noqa: E402
from selenium import webdriver  # noqa: E402 - only where a browser can run it
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

FAST = 400.0  # the simulator's speed once the page has answered


@pytest.fixture(scope="module")
def driver() -> Iterator[webdriver.Chrome]:
    """One browser for the whole walk-through, at phone size."""
    browser = chromium.browser(390, 844)
    try:
        yield browser
    finally:
        browser.quit()


# ------------------------------------------------------------------ the three things


def test_send_home_and_confirm_and_the_robot_docks(driver: webdriver.Chrome) -> None:
    def attendant(url: str) -> str:
        driver.get(url)
        tap_and_confirm(driver, "Volver a la base")  # enabled once a tour runs
        give_code(driver)
        return answer(driver)

    async def main() -> tuple[str, str, str]:
        async with console_tour({"speed": 40.0}, once=True) as (run, _people, url):
            said = await asyncio.to_thread(attendant, url)
            run.sim.speed = FAST
            aborted = await run.sim.wait_for(is_("tour", state="aborted"), 60)
            await run.finish()
            return said, aborted.payload["reason"], run.sim.world.docking_state

    said, reason, docking = asyncio.run(main())
    assert said == "Hecho: termina la visita: el robot vuelve a la base y se pone a cargar"
    assert (reason, docking) == ("operator", "docked")


def test_out_of_service_and_no_tour_starts(driver: webdriver.Chrome) -> None:
    def attendant(url: str) -> str:
        driver.get(url)
        tap_and_confirm(driver, "Fuera de servicio")
        give_code(driver)
        said = answer(driver)
        button(driver, "Volver al servicio")  # the page offers the way back
        return said

    async def main() -> tuple[str, list[str], bool]:
        # the front end is ready only much later in sim time: the attendant acts first
        scenario = {"speed": 5.0, "frontend": {"idle_at": 600.0}}
        async with console_tour(scenario, once=False) as (run, _people, url):
            said = await asyncio.to_thread(attendant, url)
            run.sim.speed = FAST
            idle = await run.sim.wait_for(
                lambda r: r.direction == "out" and r.channel == "frontend_idle", 60
            )
            await run.sim.clock.sleep_until(idle.t + 60.0)  # a front end ready, a minute
            after = [r.channel for r in run.sim.received() if r.t >= idle.t]
            in_service = run.executive.core.board.get(keys.IN_SERVICE) is not False
            return said, after, in_service

    said, after, in_service = asyncio.run(main())
    assert said == "Hecho: fuera de servicio: no empezará ninguna visita nueva"
    assert not in_service
    assert "tour" not in after and "/docking/undock" not in after


def test_a_help_request_answered_with_done_and_the_robot_goes_on(
    driver: webdriver.Chrome,
) -> None:
    panel = "El robot espera a que alguien le ayude"

    def attendant_sees_help(url: str) -> None:
        driver.get(url)
        sees(driver, panel)

    def attendant_taps_done() -> str:
        button(driver, "Hecho", under=panel).click()
        give_code(driver)
        said = answer(driver)
        WebDriverWait(driver, WAIT, poll_frequency=0.05).until(  # the panel goes away
            lambda drv: (
                not any(
                    e.is_displayed()
                    for e in drv.find_elements(By.XPATH, f"//h2[normalize-space()='{panel}']")
                )
            )
        )
        return said

    async def main() -> tuple[str, bool, Any]:
        scenario = {"speed": FAST, "docking": {"dock_failures": 3}}
        async with console_tour(scenario, once=False) as (run, _people, url):
            exe = run.executive
            book = exe.staff.book
            await run.executive_ticks_until(lambda: "docking_failed" in book.active, 60)
            await asyncio.to_thread(attendant_sees_help, url)
            docking = run.sim.world.docking  # a person puts the robot on its charger
            docking.state, docking.docked = "docked", True
            await run.executive_ticks_until(lambda: _docked(exe), 30)
            said = await asyncio.to_thread(attendant_taps_done)
            await run.executive_ticks_until(lambda: "docking_failed" not in book.active, 30)
            ended = await run.sim.wait_for(is_("tour", state="ended"), 30)
            return said, exe.core.board.get(keys.HELP) is None, ended.payload

    said, helped, ended = asyncio.run(main())
    assert said.startswith("Hecho: ")
    assert helped
    assert ended["state"] == "ended"


def _docked(exe: Any) -> bool:
    reading = exe.core.board.get(keys.DOCKING)
    return reading is not None and reading.value == "docked"
