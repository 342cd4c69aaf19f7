"""The page as a drawing, not slots, in Chromium against the shipped model: any number of curves, each with its name
and colour for life; the two (three) mixed picked in the list; zoom and pan that change the view and never the
curves; the history kept across a reload; crossing in-betweens marked and taken only when asked twice; a service
warming up said so."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.e2e.test_page import arc, browser, draw, open_page, server, state  # noqa: F401 - fixtures

pytestmark = pytest.mark.integration

T = np.linspace(0, 1, 30)
STROKES = [
    list(zip(120 + 250 * T, 250 + 80 * np.sin(2 * np.pi * T))),  # a wave
    arc(520, 420, 150, 1.05 * np.pi, 1.95 * np.pi),  # a bowl
    list(zip(620 + 280 * T, 150 + 120 * T**2)),  # a ramp
    arc(300, 560, 110, 0.1 * np.pi, 0.9 * np.pi),  # a hump
]


def _settled(page, count: int) -> dict:
    """The page's state once `count` curves are read, and the mix and its in-betweens are of the curves mixed now."""
    page.wait_for_function(
        f"window.curveVae.items.length === {count} && window.curveVae.recon.every((r) => r)"
        " && window.curveVae.result !== null && window.curveVae.strip.length > 0"
        " && window.curveVae.result.of.join() === mixNames().join()"
        " && window.curveVae.stripOf.join() === mixNames().join()"
    )
    return state(page)


def _export(page) -> list[dict]:
    with page.expect_download() as download:
        page.click("#download-json")
    return json.loads(Path(download.value.path()).read_text())["curves"]


def _inputs(page) -> dict[str, list]:
    return {c["name"]: c["points"] for c in _export(page) if c["role"] == "input"}


def test_strokes_add_curves_taking_adds_one_and_none_is_renamed_or_moved(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/", width=1440, height=900)
    for k, stroke in enumerate(STROKES):
        draw(page, stroke)
        page.wait_for_function(f"window.curveVae.items.length === {k + 1}")
    s = _settled(page, 4)
    four = _inputs(page)
    assert list(four) == ["A", "B", "C", "D"]  # four strokes, four curves
    assert s["result"]["of"] == ["C", "D"]  # the last two drawn are mixed until others are picked
    colours = [page.locator(f"path.input[data-name='{n}']").get_attribute("stroke") for n in "ABCD"]
    assert len(set(colours)) == 4
    page.locator("#strip .thumb").first.click()  # the first in-between: a fifth curve
    _settled(page, 5)
    five = _inputs(page)
    assert list(five) == ["A", "B", "C", "D", "E"]
    for name in "ABCD":  # none renamed, none moved, none recoloured
        np.testing.assert_array_equal(five[name], four[name])
        assert page.locator(f"path.input[data-name='{name}']").get_attribute("stroke") == colours["ABCD".index(name)]
    assert page.locator("#curve-list li").count() == 5
    assert errors == []


def test_the_user_picks_which_curves_are_mixed(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    for stroke in STROKES[:3]:
        draw(page, stroke)
    assert _settled(page, 3)["result"]["of"] == ["B", "C"]
    page.locator("#curve-list li[data-name='A'] .mix-pick").check()  # A joins; the earliest pick of the two goes
    page.wait_for_function("JSON.stringify(window.curveVae.result.of) === JSON.stringify(['C', 'A'])")
    assert page.locator("#weight-of").inner_text() == "A" and page.locator("#weight-from").inner_text() == "C"
    picked = [page.locator(f"#curve-list li[data-name='{n}'] .mix-pick").is_checked() for n in "ABC"]
    assert picked == [True, False, True]
    page.locator("#curve-list li[data-name='C'] button.remove").click()  # deleting a mixed curve: B takes its place
    page.wait_for_function(
        "window.curveVae.items.length === 2 && window.curveVae.result !== null"
        " && window.curveVae.result.of.length === 2 && !window.curveVae.result.of.includes('C')"
    )
    assert state(page)["names"] == ["A", "B"]
    draw(page, STROKES[3])  # the next curve is D: a name is never given again
    page.wait_for_function("window.curveVae.items.length === 3")
    assert state(page)["names"] == ["A", "B", "D"]
    assert errors == []


def test_the_wheel_zooms_the_view_not_the_curves_and_the_view_is_no_step(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    for stroke in STROKES[:2]:
        draw(page, stroke)
    _settled(page, 2)
    before = _inputs(page)
    view = page.locator("#board").get_attribute("viewBox")
    box = page.locator("#board").bounding_box()
    page.mouse.move(box["x"] + 0.3 * box["width"], box["y"] + 0.4 * box["height"])
    page.mouse.wheel(0, -400)  # zoom in about the pointer
    page.wait_for_function(f"document.getElementById('board').getAttribute('viewBox') !== '{view}'")
    zoomed = [float(v) for v in page.locator("#board").get_attribute("viewBox").split()]
    assert zoomed[2] < 1000 and zoomed[3] < 700 and abs(zoomed[2] / zoomed[3] - 10 / 7) < 1e-4
    assert page.locator("#zoom-level").inner_text() != "100%"
    after = _inputs(page)
    for name in before:
        np.testing.assert_array_equal(after[name], before[name])
    assert page.locator("#undo").is_enabled()  # from the strokes; the zoom added no step:
    page.keyboard.press("Control+z")
    page.wait_for_function("window.curveVae.items.length === 1")  # one undo undid the last stroke, not the zoom
    page.click("#zoom-fit")  # fit the view to the curves
    fitted = [float(v) for v in page.locator("#board").get_attribute("viewBox").split()]
    pts = np.array(state(page)["curves"][0])
    assert fitted[0] <= pts[:, 0].min() and fitted[0] + fitted[2] >= pts[:, 0].max()
    page.click("#zoom-out")
    assert float(page.locator("#board").get_attribute("viewBox").split()[2]) > fitted[2]
    assert errors == []


def test_undo_after_a_reload_takes_the_last_curve_back(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    for stroke in STROKES[:3]:
        draw(page, stroke)
    _settled(page, 3)
    page.reload()
    page.wait_for_function("window.curveVae.items.length === 3")
    assert page.locator("#undo").is_enabled()
    page.keyboard.press("Control+z")
    page.wait_for_function("window.curveVae.items.length === 2")
    assert state(page)["names"] == ["A", "B"]
    page.reload()  # the undone step is kept as a redo too
    page.wait_for_function("window.curveVae.items.length === 2")
    page.keyboard.press("Control+y")
    page.wait_for_function("window.curveVae.items.length === 3")
    assert state(page)["names"] == ["A", "B", "C"]
    assert errors == []


def test_a_crossing_in_between_is_marked_and_taken_only_when_asked_again(browser, server):  # noqa: F811
    """The service says which in-betweens cross themselves (`valid`); here it is made to say so of the middle one."""
    page, errors = open_page(browser, server.url + "/")

    def middle_invalid(route):
        response = route.fetch()
        body = response.json()
        if len(body.get("valid", [])) == 5:
            body["valid"][2] = False
        route.fulfill(response=response, json=body)

    page.route("**/interpolate", middle_invalid)
    for stroke in STROKES[:2]:
        draw(page, stroke)
    _settled(page, 2)
    middle = page.locator("#strip .thumb").nth(2)
    assert "invalid" in (middle.get_attribute("class") or "") and "crosses itself" in middle.get_attribute("title")
    middle.click()  # asks first
    assert "crosses itself: click it again to take it anyway" in page.locator("#strip-error").inner_text()
    assert state(page)["names"] == ["A", "B"]
    middle.click()  # taken
    page.wait_for_function("window.curveVae.items.length === 3")
    assert page.locator("#strip-error").inner_text() == ""
    assert errors == []


def test_a_service_warming_up_is_said_so_until_it_is_ready(browser, server):  # noqa: F811
    page = browser.new_context().new_page()
    answers = iter(["warming", "warming"])

    def warming(route):  # GET /health as a service warming up answers it, twice, then as a warm one
        warm = next(answers, None) is None
        route.fulfill(status=200, json={"status": "ok"} if warm else {"status": "warming up", "detail": "compiling"})

    page.route("**/health", warming)
    page.goto(server.url + "/")
    page.wait_for_function("!document.getElementById('status').hidden")
    assert "warming up" in page.locator("#status").inner_text()
    page.wait_for_function("document.getElementById('status').hidden", timeout=10_000)
