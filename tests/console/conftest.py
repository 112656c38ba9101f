"""Fixtures of the console and Groot2 tests: a tree mission on the simulator, and headless Chromium."""

import shutil

import pytest
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.trees import read_mission_tree
from aeroexec.trees.runtime.runner import TreeMission
from console_helpers import TREE


@pytest.fixture
def tree_mission():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    mission = TreeMission(read_mission_tree(TREE, "groot_test.xml"), engine, name="groot_test")
    yield mission
    engine.stop()


@pytest.fixture
def browser(tmp_path):
    """Headless Chromium through Selenium, its window 1400 x 900 (``viewport`` sets another size)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    chromedriver = shutil.which("chromedriver")
    assert chromedriver, "chromedriver is not installed (.ci/run installs Debian's chromium and chromium-driver)"
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--disable-quic",
                 "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--window-size=1400,900", "--hide-scrollbars", f"--user-data-dir={tmp_path / 'chromium'}"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(chromedriver), options=options)
    yield driver
    driver.quit()
