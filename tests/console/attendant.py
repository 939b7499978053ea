"""An attendant's eyes and fingers in a real browser (Debian's Chromium, through Selenium):
every control found by its visible words and its role alone (XPath on text, no ids, no
CSS selectors), as a person reading the phone would."""

from __future__ import annotations

from typing import Any

from console_tour import TOKEN
from selenium import webdriver
from selenium.webdriver.common.by import By
from selenium.webdriver.remote.webelement import WebElement
from selenium.webdriver.support import expected_conditions
from selenium.webdriver.support.ui import WebDriverWait

WAIT = 60.0  # seconds any one thing may take to show in the page (a bound, not a pace)


# ------------------------------------------------------------------ an attendant's eyes


def _quoted(text: str) -> str:
    assert "'" not in text
    return f"'{text}'"


def button(d: webdriver.Chrome, words: str, *, under: str | None = None) -> WebElement:
    """The enabled, visible button that reads ``words`` (in the panel headed ``under``)."""
    where = f"//section[h2[normalize-space()={_quoted(under)}]]" if under else ""
    xpath = f"{where}//button[normalize-space()={_quoted(words)} and not(@disabled)]"

    def shown(drv: Any) -> WebElement | bool:
        return next((b for b in drv.find_elements(By.XPATH, xpath) if b.is_displayed()), False)

    found: WebElement = WebDriverWait(d, WAIT, poll_frequency=0.05).until(shown)
    # As a finger would: the button brought to the middle of the screen, clear of the
    # answer's banner fixed at the foot (a click there lands on the banner instead).
    d.execute_script("arguments[0].scrollIntoView({block: 'center'})", found)
    return found


def tap_and_confirm(d: webdriver.Chrome, words: str) -> None:
    """Tap the button, then tap it again where it now asks to be confirmed."""
    button(d, words).click()
    button(d, f"Pulse otra vez para confirmar: {words}").click()


def give_code(d: webdriver.Chrome) -> None:
    """The page asks for the staff code (once per session): type it in."""
    prompt = WebDriverWait(d, WAIT, poll_frequency=0.05).until(
        expected_conditions.alert_is_present()
    )
    assert prompt.text.startswith("Código de personal")
    prompt.send_keys(TOKEN)
    prompt.accept()


def answer(d: webdriver.Chrome) -> str:
    """What the page says under the buttons once the robot has answered."""
    xpath = (
        "//*[@role='status'][starts-with(normalize-space(), 'Hecho:')"
        " or starts-with(normalize-space(), 'No se ha hecho')]"
    )
    found = WebDriverWait(d, WAIT, poll_frequency=0.05).until(
        lambda drv: drv.find_elements(By.XPATH, xpath)
    )
    return str(found[0].text)


def sees(d: webdriver.Chrome, words: str) -> None:
    """Wait until ``words`` are shown somewhere on the page."""
    xpath = f"//*[normalize-space()={_quoted(words)}]"
    WebDriverWait(d, WAIT, poll_frequency=0.05).until(
        lambda drv: any(e.is_displayed() for e in drv.find_elements(By.XPATH, xpath))
    )


def gone(d: webdriver.Chrome, heading: str) -> None:
    """Wait until no panel headed ``heading`` is shown."""
    xpath = f"//h2[normalize-space()={_quoted(heading)}]"
    WebDriverWait(d, WAIT, poll_frequency=0.05).until(
        lambda drv: not any(e.is_displayed() for e in drv.find_elements(By.XPATH, xpath))
    )
