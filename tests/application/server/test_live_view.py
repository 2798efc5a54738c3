"""The live view page in a real browser: headless Chromium (Debian's chromium + chromium-driver, driven by selenium)
opens the page of a running ``robokudo serve`` on the kitchen, sends a query from the query box, and sees the tree's
nodes turn to success, the belief table gain the milk and the frame show its box; with the server stopped the page
says it is disconnected and reconnects when the server is back. A screenshot is saved in ``test-artifacts/``."""

from __future__ import annotations

import os
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.remote.webdriver import WebDriver
from selenium.webdriver.support.ui import WebDriverWait

from tests.application.server.conftest import REPO, TOKEN, Served, start_server

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
WAIT = 90.0
ARTIFACTS = REPO / "test-artifacts"


def browser_or_skip() -> None:
    if Path(CHROMIUM).exists() and Path(CHROMEDRIVER).exists():
        return
    if "CI" in os.environ:
        pytest.fail("headless Chromium is missing (make setup installs Debian's chromium and chromium-driver)")
    pytest.skip("headless Chromium is missing (make setup installs it)")


@pytest.fixture
def browser(tmp_path: Path) -> Iterator[WebDriver]:
    browser_or_skip()
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in (
        "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync", "--disable-quic",
        f"--user-data-dir={tmp_path / 'chromium'}", "--window-size=1400,1000",
    ):  # fmt: skip
        options.add_argument(flag)
    os.environ.setdefault("SE_OFFLINE", "true")  # selenium must not look for drivers online
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def page_url(served: Served, token: str | None = None) -> str:
    return f"http://{served.host}:{served.port}/" + (f"?token={token}" if token else "")


def connection_state(driver: WebDriver) -> str:
    return str(driver.find_element(By.ID, "connection").get_attribute("data-state"))


def test_a_query_sent_from_the_page_shows_the_tree_the_milk_and_its_box(browser: WebDriver, tmp_path: Path) -> None:
    served = start_server(tmp_path / "server")
    try:
        browser.get(page_url(served))
        wait = WebDriverWait(browser, WAIT, poll_frequency=0.05)
        wait.until(lambda d: connection_state(d) == "connected")
        wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, "#tree .node[data-name='idle']"))
        browser.find_element(By.ID, "query").send_keys("find milk in fridge")
        browser.find_element(By.ID, "send").click()
        wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, "#goals tr[data-status='SUCCEEDED']"))
        frame = browser.find_element(By.ID, "color-frame")
        wait.until(lambda d: frame.get_attribute("data-kind") == "analysed")
        assert int(frame.get_attribute("data-hypotheses") or 0) >= 1
        labels = [t.text for t in browser.find_elements(By.CSS_SELECTOR, "#boxes text")]
        assert any("lactose free milk" in label for label in labels), labels
        assert browser.find_elements(By.CSS_SELECTOR, "#boxes rect")
        ARTIFACTS.mkdir(exist_ok=True)
        browser.save_screenshot(str(ARTIFACTS / "live_view.png"))
        finished = browser.find_elements(By.CSS_SELECTOR, "#last-task .node[data-status='SUCCESS']")
        names = {node.get_attribute("data-name") for node in finished}
        assert {"PerceivedFrameReader", "TextReader", "AnswerStep"} <= names, names
        title = browser.find_element(By.CSS_SELECTOR, "#last-task .node[data-name='TextReader']").get_attribute("title")
        assert "why:" in (title or "")  # the planner's reason is shown on hover
        wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, "#beliefs tr[data-class='lactose free milk']"))
        row = browser.find_element(By.CSS_SELECTOR, "#beliefs tr[data-class='lactose free milk']")
        assert "fridge" in row.text
    finally:
        served.stop()


def test_the_page_says_disconnected_and_reconnects_when_the_server_returns(browser: WebDriver, tmp_path: Path) -> None:
    served = start_server(tmp_path / "first")
    port = served.port
    try:
        browser.get(page_url(served))
        wait = WebDriverWait(browser, WAIT, poll_frequency=0.05)
        wait.until(lambda d: connection_state(d) == "connected")
    finally:
        assert served.stop() == 0
    wait.until(lambda d: connection_state(d) == "disconnected")
    assert "disconnected" in browser.find_element(By.ID, "connection").text
    again = start_server(tmp_path / "second", port=port)
    try:
        wait.until(lambda d: connection_state(d) == "connected")
        wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, "#tree .node[data-name='idle']"))
    finally:
        again.stop()


def test_a_guarded_server_serves_the_page_only_with_its_token(guarded_server: Served) -> None:
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(page_url(guarded_server), timeout=10)
    assert refused.value.code == 401 and b"token" in refused.value.read()
    with urllib.request.urlopen(page_url(guarded_server, TOKEN), timeout=10) as page:
        assert page.status == 200 and b"robokudo" in page.read()


def test_unknown_paths_are_not_found(kitchen_server: Served) -> None:
    with pytest.raises(urllib.error.HTTPError) as missing:
        urllib.request.urlopen(page_url(kitchen_server) + "etc/passwd", timeout=10)
    assert missing.value.code == 404
