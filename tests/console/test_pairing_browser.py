"""A phone paired by the QR code the page shows, in real browsers (Debian's Chromium,
headless): a tablet signed in with the staff code shows the code for "Teléfono de Lucía";
the phone opens its link, keeps its own key, and steers the robot without any staff code,
recorded under its name; once ``frog-bt ctl unpair`` has revoked it, its next command is
refused and the page says so. Every control found by its visible words.

``FROG_BT_SHOTS=DIR`` also saves the pairing code's screenshot there (docs/CONSOLE.md's).
"""

from __future__ import annotations

import asyncio
import os
from pathlib import Path
from typing import Any

import chromium
import pytest
from console_tour import TOKEN, console_tour

from frog_bt.cli import main
from frog_bt.model.events import OperatorDone
from frog_bt.runtime.observer import listen

chromium.require()

from attendant import WAIT, answer, button, give_code, sees, tap_and_confirm  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

NAME = "Teléfono de Lucía"


def test_a_phone_paired_by_the_pages_qr_code_steers_under_its_name(tmp_path: Path) -> None:
    token_file = tmp_path / "console-token"
    token_file.write_text(TOKEN)
    token_file.chmod(0o600)
    tablet = chromium.browser(1024, 768)
    phone = chromium.browser(390, 844)

    def show_code(url: str) -> str:
        tablet.get(url)
        field = WebDriverWait(tablet, WAIT).until(
            lambda d: d.find_element(
                By.XPATH, "//label[span[normalize-space()='Nombre del teléfono']]//input"
            )
        )
        field.send_keys(NAME)
        button(tablet, "Mostrar un código para emparejar").click()
        give_code(tablet)
        said = answer(tablet)
        link = WebDriverWait(tablet, WAIT).until(
            lambda d: next(
                (e.text for e in d.find_elements(By.XPATH, "//p[contains(., '/pair#')]")), False
            )
        )
        qr = tablet.find_element(By.XPATH, "//*[local-name()='svg'][@aria-label='QR']")
        heading = tablet.find_element(By.XPATH, "//h2[normalize-space()='Teléfonos del personal']")
        tablet.execute_script("arguments[0].scrollIntoView({block: 'start'})", heading)
        shots = os.environ.get("FROG_BT_SHOTS")
        if shots:
            tablet.save_screenshot(str(Path(shots) / "console-pair-es-1024.png"))
        assert qr.size["width"] > 100  # drawn, not empty
        return f"{said}\n{link}"

    def pair_and_steer(link: str) -> tuple[str, str, str]:
        phone.get(link)
        sees(
            phone,
            f"Este teléfono está emparejado como {NAME}: abre la consola sin el "
            "código del personal.",
        )
        address = phone.current_url
        phone.find_element(By.XPATH, "//a[normalize-space()='Abrir la consola']").click()
        sees(phone, f"Este teléfono: {NAME}")
        tap_and_confirm(phone, "Fuera de servicio")  # no staff code asked: its own key
        return address, answer(phone), str(phone.execute_script("return location.href"))

    def unpaired_steers() -> str:
        button(phone, "Volver al servicio").click()
        words = (
            "Este teléfono ya no está emparejado: escriba el código del personal o vuelva a "
            "emparejarlo."
        )
        xpath = f"//*[normalize-space()='{words}']"
        WebDriverWait(phone, WAIT).until(lambda d: d.find_elements(By.XPATH, xpath))
        return "refused"

    async def run() -> dict[str, Any]:
        out: dict[str, Any] = {}
        async with console_tour({"speed": 20.0}, once=False, token_file=token_file) as (
            tour,
            _people,
            url,
        ):
            done: list[OperatorDone] = []
            listen(tour.executive, done.append, OperatorDone)
            said, link = (await asyncio.to_thread(show_code, url)).split("\n")
            out["said"], out["link"] = said, link
            out["address"], out["answer"], out["page"] = await asyncio.to_thread(
                pair_and_steer, link
            )
            out["unpair"] = await asyncio.to_thread(
                main,
                ["ctl", "unpair", NAME, "--console", url, "--token-file", str(token_file)],
            )
            out["after"] = await asyncio.to_thread(unpaired_steers)
            out["done"] = [(d.command, d.ok, d.by) for d in done]
            tour.executive.stop("test over")
        return out

    try:
        out = asyncio.run(run())
    finally:
        tablet.quit()
        phone.quit()
    assert out["said"].startswith("Hecho: escanee este código con el teléfono en menos de 5 min")
    assert "#" not in out["address"]  # the one-time code left the address bar at once
    assert out["answer"].startswith("Hecho: ")
    assert ("service_off", True, f"device:{NAME}") in out["done"]
    assert out["unpair"] == 0 and out["after"] == "refused"
    assert not any(ok and by == f"device:{NAME}" for c, ok, by in out["done"] if c == "service_on")


pytestmark = pytest.mark.timeout(300)
