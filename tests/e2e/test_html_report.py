"""`--html REPORT.html`: one self-contained page a person opens, checked in Debian's chromium driven headless."""

from __future__ import annotations

import os
import re
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import ROOT, Cli, fleet_manifest

CHROMIUM, CHROMEDRIVER = Path("/usr/bin/chromium"), Path("/usr/bin/chromedriver")


def _install_chromium() -> str:
    """Install Debian's chromium and its driver where they are missing; return what went wrong ('' if nothing)."""
    if CHROMIUM.exists() and CHROMEDRIVER.exists():
        return ""
    # Waiting for dpkg's lock: another suite on the machine may be installing at the same time.
    apt = ["apt-get", "-q", "-y", "-o", "DPkg::Lock::Timeout=600"]
    apt = apt if os.geteuid() == 0 else ["sudo", "-n", *apt]
    for attempt in ([*apt, "install", "chromium", "chromium-driver"], [*apt, "update"],
                    [*apt, "install", "chromium", "chromium-driver"]):
        done = subprocess.run(attempt, capture_output=True, text=True, timeout=900, check=False)
        if done.returncode == 0 and CHROMIUM.exists() and CHROMEDRIVER.exists():
            return ""
    return f"cannot install chromium with {' '.join(apt)}: {done.stderr.strip()[-300:]}"


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    """Return headless chromium driven through chromedriver, logging the page's console."""
    problem = _install_chromium()
    if problem:
        if os.environ.get("CI") == "true":
            pytest.fail(problem)
        pytest.skip(f"{problem} (run as root, or install the Debian packages chromium and chromium-driver)")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1200,1000"):
        options.add_argument(argument)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(str(CHROMEDRIVER)), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def _open(browser: Any, page: Path) -> None:
    browser.get(page.as_uri())
    errors = [entry for entry in browser.get_log("browser") if entry["level"] == "SEVERE"]
    assert errors == [], errors


def _rows(browser: Any) -> list[Any]:
    from selenium.webdriver.common.by import By

    return browser.find_elements(By.CSS_SELECTOR, "#items tbody tr.item")


@pytest.fixture(scope="module")
def fleet_report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Return the report of a batch of five items: a pass, a violation, a corrupt and a missing file, a glob's."""
    folder = tmp_path_factory.mktemp("fleet")
    manifest = fleet_manifest(folder, "note", ("cell-1", "<script>alert('x')</script>", "cell-3", "cell-4",
                                                "</script><b>bold</b>"))
    report = folder / "night.html"
    result = Cli()("check-tolerances", "--manifest", manifest, "--html", report, "-q")
    assert result.exit_code == 3, result.stderr
    return report


def test_the_page_is_one_file_that_fetches_nothing(fleet_report: Path) -> None:
    text = fleet_report.read_text()
    assert not re.search(r"<(link|img|iframe)\b|\bsrc=|url\(|@import", text)
    assert set(re.findall(r"https?://[^\s\"']+", text)) == {"http://www.w3.org/2000/svg"}  # a namespace, not a fetch


def test_a_row_per_item_filtered_sorted_and_opening_its_plots(browser: Any, fleet_report: Path) -> None:
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    _open(browser, fleet_report)
    assert browser.title == "moveplan check-tolerances --manifest fleet.csv"
    rows = _rows(browser)
    assert len(rows) == 5
    assert "smallest margin" in browser.find_element(By.ID, "summary").text
    browser.find_element(By.ID, "filter").send_keys("violation")
    assert [row.text.split()[0] for row in _rows(browser)] == ["1"]
    assert browser.find_element(By.ID, "count").text == "1 of 5 rows"
    browser.find_element(By.ID, "filter").clear()
    browser.find_element(By.ID, "filter").send_keys(" ")  # an input event with nothing to match: every row
    browser.find_element(By.ID, "filter").clear()
    Select(browser.find_element(By.ID, "verdict")).select_by_visible_text("InputError")
    assert len(_rows(browser)) == 2
    Select(browser.find_element(By.ID, "verdict")).select_by_index(0)
    margin = next(th for th in browser.find_elements(By.CSS_SELECTOR, "#items th") if th.text == "margin")
    margin.click()
    first = _rows(browser)[0]
    assert "PATH_TOLERANCE_VIOLATED" in first.text  # the smallest margin first
    first.click()
    plots = browser.find_elements(By.CSS_SELECTOR, "svg.plot")
    assert len(plots) == 6 and all(p.find_elements(By.TAG_NAME, "polyline") for p in plots)  # a joint each
    assert "wrist_1_joint: largest |error| 0.250 rad; path ±0.200" in browser.page_source
    assert [entry for entry in browser.get_log("browser") if entry["level"] == "SEVERE"] == []


def test_cells_are_text_never_markup(browser: Any, fleet_report: Path) -> None:
    from selenium.webdriver.common.by import By

    _open(browser, fleet_report)
    cells = [cell.text for cell in browser.find_elements(By.CSS_SELECTOR, "#items tbody td")]
    assert "<script>alert('x')</script>" in cells and "</script><b>bold</b>" in cells
    assert browser.find_elements(By.CSS_SELECTOR, "#items b") == []


def test_a_benchmark_report_has_a_row_per_run_opening_its_times(browser: Any, tmp_path: Path) -> None:
    from selenium.webdriver.common.by import By

    report = tmp_path / "benchmark.html"
    result = Cli()("benchmark", ROOT / "tests" / "data" / "mbm" / "problems", "--robot", "panda",
                   "--planner", "RRTConnect", "--count", "1", "--seeds", "0-1", "--html", report, "-q")
    assert result.exit_code == 0, result.stderr
    _open(browser, report)
    rows = _rows(browser)
    assert len(rows) == 6  # three scenarios, two seeds
    rows[0].click()
    bars = browser.find_elements(By.CSS_SELECTOR, "svg.plot rect")
    assert len(bars) == 7  # search, simplify, certify, timing, total, planning_time, whole_call
