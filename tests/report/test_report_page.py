"""`frog-bt report`'s HTML page in a real browser (Debian's Chromium, headless, driven by
Selenium), over a small seeded season with one tour of each help event
(scripts/corpus_run.py): at 1400 and 1024 px the tours table fits the window, one line
a tour, under readable headers that are not cut even with the sort arrow; a header click
sorts the rows, the Ending filter leaves the aborted tour, and a click on a tour opens
its details, with the help it needed. Skipped where Chromium is not installed, except in
CI (``CI=true``).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import chromium
import pytest

from frog_bt.cli import main
from tests import seasons

chromium.require()

from selenium import webdriver  # noqa: E402 - only where a browser can run it
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.remote.webelement import WebElement  # noqa: E402
from selenium.webdriver.support.ui import Select, WebDriverWait  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
from corpus_run import ACK_AFTER_S  # noqa: E402

WIDTHS = (1400, 1024)
WAIT = 10.0  # seconds any one thing may take to show in the page (a bound, not a pace)
ONE_LINE_PX = 40  # a tour's row is one line of the table's text (about 25 px)


@pytest.fixture(scope="module")
def season(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, list[str]]:
    """The report's page (a file:// URL) and the seeded kind of each tour, in order."""
    recordings, manifest = seasons.season(tmp_path_factory, "helped", **seasons.HELPED)
    out = tmp_path_factory.mktemp("season")
    kinds = [t["kind"] for t in manifest["tours"]]
    assert {"dock_help", "home", "ack_alert", "skip"} <= set(kinds)
    html = out / "season.html"
    assert main(["report", str(recordings), "-o", str(html), "--quiet"]) == 0
    return html.as_uri(), kinds


@pytest.fixture(scope="module")
def driver() -> Iterator[webdriver.Chrome]:
    browser = chromium.browser(1400, 900, "--hide-scrollbars", "--force-device-scale-factor=1")
    try:
        yield browser
    finally:
        browser.quit()


def wait(d: webdriver.Chrome) -> WebDriverWait[webdriver.Chrome]:
    return WebDriverWait(d, WAIT, poll_frequency=0.05)


def load(d: webdriver.Chrome, url: str, n: int, width: int = 1400) -> None:
    """The page afresh (unsorted, unfiltered) in a window ``width`` px wide, once its
    script has counted the tours."""
    d.set_window_size(width, 900)
    wait(d).until(lambda x: x.execute_script("return window.innerWidth") == width)
    d.get(url)
    wait(d).until(lambda x: x.find_element(By.ID, "shown").text == f"{n} of {n} tours")


def headers(d: webdriver.Chrome) -> list[WebElement]:
    return list(d.find_elements(By.CSS_SELECTOR, "#tours thead th"))


def header(d: webdriver.Chrome, name: str) -> WebElement:
    return next(h for h in headers(d) if h.text == name)


def column(d: webdriver.Chrome, name: str) -> list[str]:
    """The text of one column's cells, top to bottom, of the tours shown."""
    i = [h.text for h in headers(d)].index(name)
    return [
        r.find_elements(By.TAG_NAME, "td")[i].text
        for r in d.find_elements(By.CSS_SELECTOR, "#tours tr.row")
        if r.is_displayed()
    ]


def tour_row(d: webdriver.Chrome, number: int) -> WebElement:
    xpath = f"//table[@id='tours']//tr[@class='row'][td[1][normalize-space()='{number}']]"
    found: WebElement = d.find_element(By.XPATH, xpath)
    return found


def details(d: webdriver.Chrome, number: int) -> WebElement:
    """The details row under tour ``number``'s row (hidden until it is clicked)."""
    found: WebElement = tour_row(d, number).find_element(By.XPATH, "following-sibling::tr[1]")
    assert found.get_attribute("class") == "more"
    return found


def fits(d: webdriver.Chrome) -> dict[str, Any]:
    """The document's and the table's width against the window's."""
    got: dict[str, Any] = d.execute_script(
        "var t = document.getElementById('tours').getBoundingClientRect();"
        "return {inner: window.innerWidth, scroll: document.documentElement.scrollWidth,"
        "        left: t.left, right: t.right};"
    )
    return got


@pytest.mark.parametrize("width", WIDTHS)
def test_the_table_fits_one_line_a_tour(season, driver, width: int) -> None:
    url, kinds = season
    load(driver, url, len(kinds), width)
    where = fits(driver)
    assert where["scroll"] <= where["inner"] == width, where  # no sideways scroll
    assert where["left"] >= 0 and where["right"] <= where["inner"], where

    rows = driver.find_elements(By.CSS_SELECTOR, "#tours tr.row")
    assert len(rows) == len(kinds)
    heights = [r.rect["height"] for r in rows]
    assert max(heights) - min(heights) < 0.5 and max(heights) < ONE_LINE_PX, heights
    head = driver.find_element(By.CSS_SELECTOR, "#tours thead tr").rect["height"]
    assert head < ONE_LINE_PX, head

    # every header whole, also with its sort arrow (a click sorts by it)
    for th in headers(driver):
        th.click()
        wait(driver).until(lambda _, th=th: th.get_attribute("data-dir") == "up")
        whole = driver.execute_script(
            "var th = arguments[0]; return th.scrollWidth <= th.clientWidth;", th
        )
        assert whole, f"the header {th.text!r} is cut at {width} px"
    # and a tour's details open inside the width
    row = tour_row(driver, kinds.index("dock_help") + 1)
    row.click()
    wait(driver).until(lambda _: details(driver, kinds.index("dock_help") + 1).is_displayed())
    where = fits(driver)
    assert where["scroll"] <= where["inner"] and where["right"] <= where["inner"], where


def test_headers_and_cells_read_as_words(season, driver) -> None:
    url, kinds = season
    load(driver, url, len(kinds))
    names = [h.text for h in headers(driver)]
    assert len(names) == 11 and {"#", "Day", "Start", "Min", "Ending", "Incidents"} <= set(names)
    for name in names:
        assert name == "#" or re.fullmatch(r"[A-Z][a-z]+( [a-z]+)*", name), name

    cells = [td.text for td in driver.find_elements(By.CSS_SELECTOR, "#tours tr.row td")]
    assert len(cells) == len(names) * len(kinds)
    for text in cells:
        assert not re.search(r"\b(True|False|None|nan|null)\b", text), text
        assert not re.search(r"\d{4}-\d\d-\d\dT\d\d:", text), text  # an ISO timestamp
    assert column(driver, "#") == [str(n) for n in range(1, len(kinds) + 1)]
    assert all(re.fullmatch(r"2026-06-0[12]", t) for t in column(driver, "Day"))
    assert all(re.fullmatch(r"\d\d:\d\d", t) for t in column(driver, "Start"))
    assert all(re.fullmatch(r"\d+\.\d", t) for t in column(driver, "Min"))
    assert all(re.fullmatch(r"\d of \d", t) for t in column(driver, "Stops"))


def test_a_header_click_sorts(season, driver) -> None:
    url, kinds = season
    load(driver, url, len(kinds))
    start = [float(m) for m in column(driver, "Min")]
    assert start != sorted(start) and start != sorted(start, reverse=True)  # a test

    header(driver, "Min").click()
    wait(driver).until(lambda _: header(driver, "Min").get_attribute("data-dir") == "up")
    up = [float(m) for m in column(driver, "Min")]
    assert up == sorted(start)
    header(driver, "Min").click()
    wait(driver).until(lambda _: header(driver, "Min").get_attribute("data-dir") == "down")
    assert [float(m) for m in column(driver, "Min")] == sorted(start, reverse=True)
    # a row keeps its details beneath it
    first = int(column(driver, "#")[0])
    assert details(driver, first).get_attribute("hidden") is not None

    # by text: the skipped tour's "POI3 (operator)" first, descending
    header(driver, "Skipped").click()
    header(driver, "Skipped").click()
    wait(driver).until(lambda _: header(driver, "Skipped").get_attribute("data-dir") == "down")
    skipped = column(driver, "Skipped")
    assert skipped[0] == "POI3 (operator)" and not any(skipped[1:]), skipped
    assert column(driver, "#")[0] == str(kinds.index("skip") + 1)

    header(driver, "#").click()
    wait(driver).until(lambda _: header(driver, "#").get_attribute("data-dir") == "up")
    assert column(driver, "#") == [str(n) for n in range(1, len(kinds) + 1)]


def test_the_ending_filter_leaves_the_aborted_tour(season, driver) -> None:
    url, kinds = season
    load(driver, url, len(kinds))
    aborted = [str(n) for n, k in enumerate(kinds, 1) if k in ("home", "fault")]
    assert aborted  # the operator's home

    Select(driver.find_element(By.ID, "f-ending")).select_by_value("aborted")
    wait(driver).until(
        lambda x: x.find_element(By.ID, "shown").text == f"{len(aborted)} of {len(kinds)} tours"
    )
    assert column(driver, "#") == aborted
    assert column(driver, "Ending") == ["aborted: operator"] * len(aborted)

    Select(driver.find_element(By.ID, "f-ending")).select_by_value("ended")
    wait(driver).until(
        lambda x: (
            x.find_element(By.ID, "shown").text
            == f"{len(kinds) - len(aborted)} of {len(kinds)} tours"
        )
    )
    assert set(column(driver, "Ending")) == {"ended"}
    assert not set(column(driver, "#")) & set(aborted)


def test_a_click_opens_a_tour_and_its_help(season, driver) -> None:
    url, kinds = season
    load(driver, url, len(kinds))
    dock = kinds.index("dock_help") + 1
    more = details(driver, dock)
    assert not more.is_displayed()
    incidents = column(driver, "Incidents")[dock - 1]
    assert "help needed: docking_failed" in incidents

    tour_row(driver, dock).click()
    wait(driver).until(lambda _: more.is_displayed())
    said = dict(
        zip(
            (t.text for t in more.find_elements(By.TAG_NAME, "dt")),
            (t.text for t in more.find_elements(By.TAG_NAME, "dd")),
            strict=True,
        )
    )
    assert said["Stops reached"] == "POI1 → POI2 → POI3 → POI4 → POI5 → END", said
    assert said["Stops played"] == said["Stops reached"], said
    # the answer, who sent it, and no refusal before it (the person answered once docked)
    assert re.fullmatch(r"\+[\d.]+ s done_by_hand \(ok\) by console", said["Operator"]), said
    assert "docking_failed (ERROR)" in said["Alerts"], said
    assert said["Incidents"] == incidents
    # the others stay closed; a second click closes it
    assert sum(m.is_displayed() for m in driver.find_elements(By.CSS_SELECTOR, "tr.more")) == 1
    tour_row(driver, dock).click()
    wait(driver).until(lambda _: not more.is_displayed())

    acked = kinds.index("ack_alert") + 1
    tour_row(driver, acked).click()
    wait(driver).until(lambda _: details(driver, acked).is_displayed())
    alerts = details(driver, acked).find_element(
        By.XPATH, ".//dt[.='Alerts']/following-sibling::dd"
    )
    acked_after = re.search(r"battery_low \(WARN\), acknowledged after ([\d.]+) s", alerts.text)
    assert acked_after, alerts.text
    assert float(acked_after[1]) == pytest.approx(ACK_AFTER_S, abs=1.0)  # as seeded
