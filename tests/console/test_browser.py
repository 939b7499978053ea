"""The console in a real browser: Debian's Chromium, headless, driven by Selenium with
Debian's chromium-driver. It opens the console of a running simulated tour, sees the stop
change, presses "Send home" with the token, and the simulated robot docks with
``tour aborted`` and the reason ``operator``.

Skipped (and saying why) where Chromium is not installed, except in CI (``CI=true``),
where ``.ci/run`` installs it and the test must run.
"""

from __future__ import annotations

import asyncio

import chromium
from console_tour import TOKEN, console_tour
from test_faults import is_

chromium.require()

from selenium import webdriver  # noqa: E402 - only where a browser can run it
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.support import expected_conditions  # noqa: E402
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

WAIT = 60.0  # seconds any one thing may take to show in the page (a bound, not a pace)


def browser() -> webdriver.Chrome:
    return chromium.browser(1280, 1600)


def drive(url: str) -> tuple[list[str], str]:
    """In the browser: the stops seen, in order, then Send home; the answer shown."""
    driver = browser()
    try:
        wait = WebDriverWait(driver, WAIT, poll_frequency=0.05)
        driver.get(url)
        stop = driver.find_element(By.ID, "stop")
        # stops by the names staff know them by, in the site's language (es)
        wait.until(lambda d: stop.text == "Muralla almohade")
        seen = [stop.text]
        wait.until(lambda d: stop.text == "Patio de la Montería")  # the stop changes
        seen.append(stop.text)
        home = driver.find_element(By.CSS_SELECTOR, "button[data-command=home]")
        home.click()  # one tap arms it, the second confirms
        wait.until(lambda d: home.text.startswith("Pulse otra vez"))
        home.click()
        prompt = wait.until(expected_conditions.alert_is_present())
        prompt.send_keys(TOKEN)
        prompt.accept()
        answer = driver.find_element(By.ID, "answer")
        wait.until(lambda d: answer.text.startswith(("Hecho", "No se ha hecho")))
        return seen, answer.text
    finally:
        driver.quit()


def test_send_home_from_the_console_in_chromium() -> None:
    async def main() -> tuple[list[str], str, str, str, str]:
        # slow enough for a person (and a browser) to follow: a stop lasts a few seconds
        async with console_tour({"speed": 40.0}, once=True) as (run, _people, url):
            seen, answer = await asyncio.to_thread(drive, url)
            aborted = await run.sim.wait_for(is_("tour", state="aborted"), 60)
            outcome = await run.finish()
            return (
                seen,
                answer,
                aborted.payload["reason"],
                outcome.reason,
                run.sim.world.docking_state,
            )

    seen, answer, reason, outcome, docking = asyncio.run(main())
    assert seen == ["Muralla almohade", "Patio de la Montería"]
    # the page speaks the site's language (config/site.yaml: es)
    assert answer == "Hecho: termina la visita: el robot vuelve a la base y se pone a cargar"
    assert (reason, outcome, docking) == ("operator", "tour aborted: operator", "docked")
