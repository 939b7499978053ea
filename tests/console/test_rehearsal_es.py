"""The rehearsal docs/CONSOLE.md walks a new attendant through, in a real browser, in
Spanish, by visible words only: ``frog-bt demo --console --scenario NAME`` for each
scenario in which the robot asks for a person (``dock_fails``, ``undock_fails``,
``home_fails``, ``fault_persists``). The page shows the panel, the attendant taps
*Hecho* (the demo does the step in the simulator, as a person would) or *Reintentar*
(the scenario's failures have run out), the page says it was done, the panel goes away,
and the executive is still running: the demo never exits on its own.

The executive runs as the demo runs it: the shipped scenario (faster, shorter content),
not ``--once``, with the rehearsal's hands lent (:meth:`Rehearsal.lend_hands`).
"""

from __future__ import annotations

import asyncio
from collections.abc import Iterator

import chromium
import pytest
from console_tour import TOKEN
from tour import FAST, after_ticks

from frog_bt.commands.console_options import ConsoleSettings, start_people
from frog_bt.config import load_site
from frog_bt.model import keys
from frog_bt.rehearsal import Rehearsal
from frog_bt.sim import scenario_from

chromium.require()

from attendant import answer, button, give_code, gone, sees  # noqa: E402
from selenium import webdriver  # noqa: E402 - only where a browser can run it

PANEL = "El robot espera a que alguien le ayude"


@pytest.fixture(scope="module")
def driver() -> Iterator[webdriver.Chrome]:
    browser = chromium.browser(390, 844)
    try:
        yield browser
    finally:
        browser.quit()


def _walk(driver: webdriver.Chrome, url: str, words: str) -> str:
    """The attendant opens the page, sees the panel, taps ``words``, gives the code and
    reads the answer; the panel goes away."""
    driver.get(url)
    sees(driver, PANEL)
    button(driver, words, under=PANEL).click()
    give_code(driver)
    said = answer(driver)
    gone(driver, PANEL)
    return said


async def _rehearse(driver: webdriver.Chrome, name: str, words: str) -> tuple[str, bool, str]:
    site = load_site()
    rehearsal = Rehearsal(scenario_from(name, FAST), site=site, once=False, memory=True)
    async with rehearsal:
        exe = rehearsal.executive
        people = await start_people(exe, ConsoleSettings("127.0.0.1", 0, TOKEN), [])
        try:
            assert people.console is not None
            rehearsal.lend_hands()
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None, 90)
            rehearsal.sim.speed = 2.0  # the demo's pace while a person acts
            url = f"http://127.0.0.1:{people.console.bound_port}"
            said = await asyncio.to_thread(_walk, driver, url, words)
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is None, 30)
            if words == "Reintentar" and name == "dock_fails":  # the fourth dock works
                rehearsal.sim.speed = FAST["speed"]
                await after_ticks(exe, lambda: rehearsal.sim.world.docking_state == "docked", 60)
            running = rehearsal.task is not None and not rehearsal.task.done()
            return said, running, rehearsal.sim.world.docking_state
        finally:
            await people.close()


@pytest.mark.parametrize(
    ("name", "words", "done", "docking"),
    [
        ("dock_fails", "Hecho", "seguimos: alguien ha puesto el robot en su cargador", "docked"),
        ("undock_fails", "Hecho", "seguimos: alguien ha sacado el robot del cargador", "undocked"),
        ("home_fails", "Hecho", "seguimos: alguien ha puesto el robot en su cargador", "docked"),
        ("fault_persists", "Hecho", "seguimos: alguien ha resuelto la avería", None),
        ("dock_fails", "Reintentar", "lo vuelve a intentar: acoplarse al cargador", "docked"),
        ("undock_fails", "Reintentar", "lo vuelve a intentar: salir del cargador", None),
        ("home_fails", "Reintentar", "lo vuelve a intentar: volver a la base", None),
    ],
)
def test_each_help_scenario_is_answered_and_the_demo_goes_on(
    driver: webdriver.Chrome, name: str, words: str, done: str, docking: str | None
) -> None:
    said, running, state = asyncio.run(_rehearse(driver, name, words))
    assert said.startswith("Hecho: "), said
    assert done in said, said
    assert running  # the executive runs on: the demo does not exit on its own
    if docking is not None:
        assert state == docking  # where a person put it
