"""The page as a drawing tool, in Chromium against the shipped model: undo and redo (keys and buttons), the drawing and
its history kept across a reload, Clear a step like any other, a curve selected to delete or to edit by its control
points, an in-between taken as a new curve, the neighbours of a selected curve (POST /explore) taken as a new curve,
the sweep animated and as a sheet, a legend, the vase never stale, and a layout that keeps the files and the vase in
view."""

from __future__ import annotations

import json
from pathlib import Path

import httpx
import numpy as np
import pytest

from tests.e2e.test_page import arc, browser, draw, open_page, server, state  # noqa: F401 - fixtures

pytestmark = pytest.mark.integration

BOWL = arc(300, 380, 150, 1.05 * np.pi, 1.95 * np.pi)
HUMP = arc(680, 330, 170, 0.1 * np.pi, 0.9 * np.pi)


def _two(page) -> dict:
    draw(page, BOWL)
    draw(page, HUMP)
    page.wait_for_function("window.curveVae.result !== null && window.curveVae.strip.length === 5")
    return state(page)


def _settled(page, count: int, mixed: int = 2) -> dict:
    page.wait_for_function(
        f"window.curveVae.curves.length === {count} && window.curveVae.recon.every((r) => r)"
        f" && ({count} < {mixed} || (window.curveVae.result !== null && window.curveVae.strip.length > 0))"
    )
    return state(page)


def _click_board(page, point: tuple[float, float]) -> None:
    box = page.locator("#board").bounding_box()
    page.mouse.click(box["x"] + point[0] / 1000 * box["width"], box["y"] + point[1] / 700 * box["height"])


def _json_export(page) -> dict:
    button = page.get_by_role("button", name="JSON", exact=True)
    assert button.inner_text() == "JSON"
    with page.expect_download() as download:
        button.click()
    return json.loads(Path(download.value.path()).read_text())


def test_undo_redo_and_a_reload_keep_the_drawing(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/", width=1440, height=1000)
    drawn = _two(page)["curves"]
    inputs = [c for c in _json_export(page)["curves"] if c["role"] == "input"]
    assert [c["name"] for c in inputs] == ["A", "B"]  # two strokes, two curves
    np.testing.assert_allclose([c["points"] for c in inputs][1], drawn[1])

    page.keyboard.press("Control+z")
    assert len(_settled(page, 1)["curves"]) == 1 and page.locator("#redo").is_enabled()
    page.keyboard.press("Control+Shift+z")
    np.testing.assert_allclose(_settled(page, 2)["curves"], drawn)
    page.keyboard.press("Control+z")
    _settled(page, 1)
    page.keyboard.press("Control+y")
    _settled(page, 2)
    page.click("#undo")
    _settled(page, 1)
    page.click("#redo")
    _settled(page, 2)

    page.locator("#weight").fill("0.25")
    page.wait_for_function("window.curveVae.result.weights[1] === 0.25")
    page.reload()
    kept = _settled(page, 2)
    np.testing.assert_allclose(kept["curves"], drawn)
    assert kept["weight"] == 0.25 and page.locator("#weight-value").inner_text() == "0.25"

    page.click("#clear")  # a step like any other: the empty drawing is kept, and Undo brings the curves back
    assert state(page)["curves"] == [] and state(page)["vase"] is None
    page.reload()
    assert state(page)["curves"] == [] and "Draw a curve here" in page.locator("#board").text_content()
    assert page.locator("#undo").is_enabled()
    page.keyboard.press("Control+z")
    np.testing.assert_allclose(_settled(page, 2)["curves"], drawn)
    assert errors == []


def test_a_selected_curve_is_deleted_or_edited_by_its_control_points(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    before = _two(page)["curves"]
    _click_board(page, HUMP[12])  # a click on B selects it
    page.wait_for_function("window.curveVae.selected === 1")
    assert page.locator("path.input.selected").get_attribute("data-name") == "B"
    page.keyboard.press("Delete")
    after = _settled(page, 1)
    np.testing.assert_allclose(after["curves"][0], before[0])  # A stays
    assert after["names"] == ["A"]
    page.keyboard.press("Control+z")
    _settled(page, 2)
    _click_board(page, BOWL[15])  # select A: its control points are handles
    page.wait_for_function("window.curveVae.selected === 0 && document.querySelectorAll('circle.handle').length > 0")
    handles = page.locator("circle.handle")
    assert handles.count() == 31
    grab = handles.nth(15)
    box = grab.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x, y - 40, steps=5)  # up by 40 screen pixels
    page.mouse.up()
    edited = _settled(page, 2)  # the edited spline is A's now, and read again
    assert edited["names"] == ["A", "B"] and edited["selected"] == 0
    np.testing.assert_allclose(edited["curves"][1], before[1])  # B as it was
    lifted = np.array(edited["curves"][0])[:, 1].max() - np.array(before[0])[:, 1].max()
    assert lifted > 5, lifted  # the bowl's middle came up (API y points up)
    page.keyboard.press("Control+z")  # the edit is a step
    np.testing.assert_allclose(_settled(page, 2)["curves"][0], before[0])
    _click_board(page, (950, 50))  # a click on nothing selects nothing
    assert state(page)["selected"] is None and page.locator("#board-error").inner_text() == ""
    assert errors == []


def test_an_in_between_is_taken_as_a_new_curve_with_its_weights_shown(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    s = _two(page)
    thumbs = page.locator("#strip .thumb")
    assert [thumbs.nth(i).locator(".caption").inner_text() for i in range(5)] == [
        "A 100%",
        "A 75%, B 25%",
        "A 50%, B 50%",
        "A 25%, B 75%",
        "B 100%",
    ]
    thumbs.nth(2).click()  # the middle in-between: a new curve C; A and B as they were
    taken = _settled(page, 3)
    assert taken["names"] == ["A", "B", "C"]
    np.testing.assert_allclose(taken["curves"][:2], s["curves"])
    np.testing.assert_allclose(taken["curves"][2], s["strip"][2])
    page.keyboard.press("Control+z")
    np.testing.assert_allclose(_settled(page, 2)["curves"], s["curves"])
    # the sweep on the page: one path whose outline runs through the five in-betweens and back
    values = page.locator("#sweep-preview animate").get_attribute("values")
    assert values is not None and len(values.split(";")) == 9
    assert page.locator("#sweep-caption").inner_text() == "the sweep, animated"
    with page.expect_download() as download:
        page.click("#download-sheet")
    sheet = Path(download.value.path()).read_text()
    assert sheet.count('class="interpolant"') == 5 and "0.75 A + 0.25 B" in sheet
    assert errors == []


def test_the_neighbours_of_a_selected_curve_are_the_services_and_one_is_taken(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    s = _two(page)
    assert page.locator("#around").is_hidden()
    _click_board(page, BOWL[15])
    page.wait_for_function("window.curveVae.neighbours !== null && window.curveVae.neighbours.of === 'A'")
    assert page.locator("#around").is_visible() and page.locator("#around-title").inner_text() == "Around A"
    grid = page.locator("#neighbours .thumb")
    assert grid.count() == 9 and grid.nth(4).locator(".caption").inner_text() == "itself"
    body = {"curves": [s["curves"][0]], "steps": 3, "directions": 2, "n_points": 60, "refine": 0}
    answer = httpx.post(server.url + "/explore", json=body, timeout=30).json()
    np.testing.assert_allclose(state(page)["neighbours"]["curves"], answer["curves"], atol=1e-9)
    grid.nth(8).click()  # +1σ along both directions: a new curve C, A still selected, its grid still A's
    page.wait_for_function(
        "window.curveVae.curves.length === 3 && window.curveVae.recon.every((r) => r) && window.curveVae.neighbours"
        " && window.curveVae.selected === 0"
    )
    taken = state(page)
    assert taken["names"] == ["A", "B", "C"]
    np.testing.assert_allclose(taken["curves"][2], answer["curves"][8])
    np.testing.assert_allclose(taken["curves"][:2], s["curves"])
    page.keyboard.press("Escape")
    assert page.locator("#around").is_hidden()
    assert errors == []


def test_a_legend_says_what_is_shown_and_the_vase_is_never_stale(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/", width=1440, height=900)
    legend = page.locator("[aria-label=legend]").inner_text()
    assert "reconstruction" in legend and "mix" in legend and "control polygon" in legend
    assert page.locator("#vase-view").is_hidden()  # no empty box before a vase
    _two(page)
    labels = page.locator("#board text.label")
    assert labels.all_text_contents() == ["A", "B", "mix"]
    on_board = [c for c in state(page)["curves"] + [state(page)["result"]["points"]]]
    for i in range(3):  # each name sits off every curve, not on one
        x, y = (float(labels.nth(i).get_attribute(k)) for k in ("x", "y"))
        gap = min(np.hypot(np.array(c)[:, 0] - x, 700 - np.array(c)[:, 1] - y).min() for c in on_board)
        assert gap >= 12, (labels.nth(i).text_content(), gap)
    page.click("#vase")
    page.wait_for_function("window.curveVae.vase !== null")
    assert page.locator("#vase-view").is_visible()
    for selector in ("#download-json", "#download-dxf", "#vase-view", "#download-stl"):  # in view at 1440×900
        box = page.locator(selector).bounding_box()
        assert box is not None and box["y"] + box["height"] <= 900, (selector, box)
    assert page.locator("#curl").is_hidden()  # the curl command on demand
    page.check("#mode-triplet")  # the vase was the pair's mix: gone with it
    page.wait_for_function("window.curveVae.vase === null")
    assert page.locator("#vase-view").is_hidden()
    draw(page, arc(480, 560, 100, 0.1 * np.pi, 0.9 * np.pi))  # a third curve: the triangle and its grid
    page.wait_for_function("window.curveVae.result !== null && window.curveVae.strip.length === 10")
    page.click("#vase")
    page.wait_for_function("window.curveVae.vase !== null")
    for selector in ("#download-sheet", "#strip .thumb >> nth=9", "#triangle"):  # still in view with the grid
        box = page.locator(selector).bounding_box()
        assert box is not None and box["y"] + box["height"] <= 900, (selector, box)
    assert page.locator("#triangle").bounding_box()["width"] >= 200  # a triangle big enough to aim in
    # the side column scrolls on its own (the list of curves grows): the vase comes into view there
    page.locator("#vase-view").scroll_into_view_if_needed()
    box = page.locator("#vase-view").bounding_box()
    assert box is not None and box["y"] + box["height"] <= 900 + 1  # (a pixel's rounding at the scroll's end)
    assert errors == []
