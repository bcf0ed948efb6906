"""The explorer: its lessons as functions, its command, and the app driven in a real browser."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from signorini.cli.app import main
from signorini.output import lessons
from signorini.output.lesson_figures import hertz_figure, prices_figure, race_figure, uzawa_figure
from signorini.output.lesson_html import (certificate_table, figure_image, number, numbers_table,
                                          race_table)

ROOT = Path(__file__).resolve().parents[1]
SCREENSHOT = ROOT / "docs" / "tutorials" / "explore.png"
CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--no-first-run", "--disable-sync"]
WAIT_MS = 60_000


# -- the lessons as functions -------------------------------------------------------------------
def test_uzawa_converges_below_the_bound_and_diverges_past_it():
    bound = lessons.uzawa_step_bound()
    W, _, _ = lessons.dual_function(lessons.bogie())
    assert bound == pytest.approx(2 / np.linalg.eigvalsh(W)[-1], rel=1e-6)
    below, past = lessons.uzawa_lesson(0.95 * bound), lessons.uzawa_lesson(1.1 * bound)
    assert below.result.status == "converged"
    assert np.allclose(below.result.force, below.maximiser, rtol=1e-4)
    assert past.result.status == "diverged"
    assert 0 < len(past.iterates) <= lessons.DRAWN_ITERATES
    assert np.allclose(below.iterates[1], below.rho * np.maximum(below.b, 0), rtol=1e-9)


def test_hertz_lesson_follows_hertz_and_its_load():
    light, heavy = lessons.hertz_lesson(0.004), lessons.hertz_lesson(0.008, E=2.0, nu=0.25)
    for lesson in (light, heavy):
        assert lesson.result.status == "converged"
        assert lesson.a == pytest.approx(lesson.a_ref, rel=0.02)
        assert lesson.p0 == pytest.approx(lesson.p0_ref, rel=0.02)
        assert lesson.result.total_force == pytest.approx(lesson.P, rel=1e-8)
        assert np.all(np.diff(lesson.x) >= 0)
        assert lesson.x[lesson.active].max() < 1.2 * lesson.a_ref
    # a ∝ √(P R / E*): twice the load on twice the modulus (E* with ν) moves a as Hertz says
    star = [lesson.E / (1 - lesson.nu**2) for lesson in (light, heavy)]
    assert heavy.a_ref / light.a_ref == pytest.approx(np.sqrt(2 * star[0] / star[1]), rel=1e-9)


@pytest.mark.parametrize("gap", [0.3, 1.0, 3.0])
def test_prices_are_the_forces(gap):
    lesson = lessons.prices_lesson(gap)
    assert lesson.result.status == "converged"
    assert lesson.envelope_error < 1e-6
    assert (lesson.force[1] > 0) == (gap < 2.0)   # the wheel lifts off the rail far enough down
    assert lesson.curve_energy.shape == lesson.curve_gaps.shape


def test_race_runs_each_method_once():
    rows = lessons.race_lesson(["pdas", "uzawa"], 1e-6)
    assert [row.method for row in rows] == ["pdas", "uzawa"]
    assert rows[0].status == "converged" and rows[1].iterations > rows[0].iterations
    assert rows[0].worst[1] <= 1e-6


def cell(table: str, element: str) -> str:
    """The text of the element with ``id=element`` in an HTML snippet."""
    found = re.findall(rf'id="{element}"[^>]*>([^<]*)<', table)
    assert len(found) == 1, f"{element}: {found}"
    return found[0]


def test_figures_and_tables_show_the_lesson(saved_figures):
    lesson = lessons.uzawa_lesson(0.2)
    image = figure_image(uzawa_figure(lesson), "u", "alt")
    assert image.startswith('<img id="u"') and "base64," in image
    step = saved_figures[-1].axes[2]
    assert step.get_lines()[0].get_xdata()[0] == pytest.approx(lesson.bound)  # the bound marked
    table = certificate_table("x", lesson.result)
    assert cell(table, "x-status") == lesson.result.status
    assert cell(table, "x-kkt-natural") == number(lesson.result.certificate.natural)
    assert cell(numbers_table("p", {"a": ("a", 1.5)}), "p-a") == "1.5"
    rows = lessons.race_lesson(["pdas"], 1e-8)
    assert cell(race_table(rows), "race-pdas-iterations") == str(rows[0].iterations)
    for fig in (hertz_figure(lessons.hertz_lesson(0.005)), prices_figure(lessons.prices_lesson(0.5)),
                race_figure(rows)):
        assert fig.axes and all(ax.has_data() for ax in fig.axes)


@pytest.mark.parametrize("argv, said", [(["--port", "0"], "--port 0 is not a port"),
                                        (["--port", "70000"], "--port 70000 is not a port")])
def test_explore_refuses_a_bad_port(argv, said, capsys):
    assert main(["explore", "--no-browser", *argv]) == 2
    assert said in capsys.readouterr().err


def test_explore_refuses_a_port_in_use(capsys):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main(["explore", "--no-browser", "--port", str(port)]) == 2
    assert f"--port {port} is in use" in capsys.readouterr().err


def test_explore_serves_with_marimo_headless_only_without_a_browser():
    from signorini.cli.explore import server_command

    headless, browsing = server_command(8800, open_browser=False), server_command(8800, True)
    assert headless[:3] == [sys.executable, "-m", "marimo"] and "--headless" in headless
    assert "--headless" not in browsing
    assert headless[headless.index("--port") + 1] == "8800"
    assert Path(headless[headless.index("run") + 1]).is_file()


# -- the app in a real browser ------------------------------------------------------------------
def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.fixture(scope="module")
def explorer():
    """The explorer served by ``signorini explore --no-browser`` and a headless chromium page."""
    pytest.importorskip("marimo", reason="the explorer needs marimo: pip install 'signorini[explore]'")
    sync_api = pytest.importorskip("playwright.sync_api",
                                   reason="the browser test needs playwright: pip install 'signorini[test]'")
    if not CHROMIUM.exists():
        pytest.skip("the browser test needs Debian's chromium at /usr/bin/chromium "
                    "(apt-get install chromium; `make` installs it as root on Debian)")
    port = free_port()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    server = subprocess.Popen([sys.executable, "-m", "signorini.cli", "explore", "--no-browser",
                               "--port", str(port)], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
    try:
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1280, "height": 1000})
            page.set_default_timeout(WAIT_MS)
            for _ in range(120):  # the server takes a few seconds to listen
                if server.poll() is not None:
                    pytest.fail(f"signorini explore stopped: {server.stdout.read()}")
                with socket.socket() as probe:
                    if probe.connect_ex(("127.0.0.1", port)) == 0:
                        break
                page.wait_for_timeout(500)
            requested: list[str] = []
            page.on("request", lambda request: requested.append(request.url))
            page.goto(f"http://127.0.0.1:{port}")
            for element in ("uzawa-figure", "hertz-figure", "prices-figure", "race-figure"):
                page.locator(f"#{element}").wait_for()
            yield page, sync_api.expect, requested, f"http://127.0.0.1:{port}/"
            browser.close()
    finally:
        server.terminate()
        try:
            code = server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait(timeout=30)
            code = None
    assert code == 128 + signal.SIGTERM, "signorini explore did not stop cleanly on SIGTERM"


def move(page, name: str, value: float) -> None:
    """Set the range input ``name`` to ``value`` as a release of the slider does."""
    page.locator(f"input[type=range][name={name}]").fill(str(value))


def shown(page, element: str) -> str:
    return page.locator(f"#{element}").inner_text().strip()


def wait_for_number(page, expect, element: str, value: float) -> None:
    expect(page.locator(f"#{element}")).to_have_text(number(value), timeout=WAIT_MS)


def test_uzawa_slider_re_solves_and_diverges_past_the_bound(explorer):
    page, expect, _, _ = explorer
    before = page.locator("#uzawa-figure").get_attribute("src")
    lesson = lessons.uzawa_lesson(0.2)
    move(page, "rho", 0.2)
    wait_for_number(page, expect, "uzawa-rho", 0.2)
    assert shown(page, "uzawa-status") == lesson.result.status
    assert shown(page, "uzawa-iterations") == number(lesson.result.iterations)
    assert shown(page, "uzawa-kkt-natural") == number(lesson.result.certificate.natural)
    assert page.locator("#uzawa-figure").get_attribute("src") != before
    bound = float(shown(page, "uzawa-bound"))
    assert bound == pytest.approx(lesson.bound, rel=1e-5)
    move(page, "rho", 0.3)
    assert 0.3 > bound
    wait_for_number(page, expect, "uzawa-rho", 0.3)
    expect(page.locator("#uzawa-status")).to_have_text("diverged", timeout=WAIT_MS)
    page.locator("input[type=range][name=rho]").scroll_into_view_if_needed()
    SCREENSHOT.parent.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SCREENSHOT))
    assert SCREENSHOT.stat().st_size > 10_000


def test_hertz_sliders_re_solve(explorer):
    page, expect, _, _ = explorer
    before = page.locator("#hertz-figure").get_attribute("src")
    move(page, "load", 0.01)
    lesson = lessons.hertz_lesson(0.01)
    wait_for_number(page, expect, "hertz-a", lesson.a)
    assert shown(page, "hertz-p0") == number(lesson.p0)
    assert shown(page, "hertz-active") == number(int(lesson.active.sum()))
    assert shown(page, "hertz-status") == lesson.result.status
    assert page.locator("#hertz-figure").get_attribute("src") != before
    move(page, "E", 2.0)
    wait_for_number(page, expect, "hertz-a_ref", lessons.hertz_lesson(0.01, 2.0).a_ref)
    move(page, "nu", 0.25)
    lesson = lessons.hertz_lesson(0.01, 2.0, 0.25)
    wait_for_number(page, expect, "hertz-a_ref", lesson.a_ref)
    wait_for_number(page, expect, "hertz-a", lesson.a)
    assert shown(page, "hertz-status") == lesson.result.status


def test_prices_slider_re_solves(explorer):
    page, expect, _, _ = explorer
    before = page.locator("#prices-figure").get_attribute("src")
    move(page, "gap", 1.0)
    lesson = lessons.prices_lesson(1.0)
    wait_for_number(page, expect, "prices-force2", lesson.force[1])
    assert float(shown(page, "prices-price2")) == pytest.approx(lesson.prices[1], rel=1e-5)
    assert float(shown(page, "prices-miss")) < 1e-6
    assert shown(page, "prices-status") == lesson.result.status
    assert page.locator("#prices-figure").get_attribute("src") != before
    move(page, "gap", 2.2)  # the rail lowered under wheel 2 until the wheel lifts off: no force, no price
    lesson = lessons.prices_lesson(2.2)
    assert lesson.force[1] == 0
    wait_for_number(page, expect, "prices-force2", lesson.force[1])
    assert float(shown(page, "prices-price2")) == pytest.approx(0.0, abs=1e-6 * lesson.force[0])
    assert shown(page, "prices-status") == lesson.result.status


def test_race_slider_re_solves(explorer):
    page, expect, _, _ = explorer
    picked = [re.sub(r"^race-", "", row.get_attribute("id"))
              for row in page.locator("#race-table tr[id]").all()]
    assert "pdas" in picked
    before = page.locator("#race-figure").get_attribute("src")
    move(page, "tol", -5)
    rows = lessons.race_lesson(picked, 1e-5)
    for row in rows:
        expect(page.locator(f"#race-{row.method}-iterations")).to_have_text(str(row.iterations),
                                                                             timeout=WAIT_MS)
        assert shown(page, f"race-{row.method}-status") == row.status
    assert page.locator("#race-figure").get_attribute("src") != before


def test_the_page_asks_nothing_of_the_network(explorer):
    page, _, requested, served = explorer
    page.wait_for_load_state("networkidle")
    outside = [url for url in requested if not url.startswith((served, "data:", "blob:"))]
    assert requested and not outside, f"requests that leave the machine: {outside}"
