"""The page with files, in Chromium against the shipped model: curves opened from the files people have (the page's
own exports, an Inkscape drawing, an airfoil with notes) by picking or dropping them, the DXF it downloads read by
ezdxf, and what it shows after Clear, with samples, and with names that would collide."""

from __future__ import annotations

import json

import numpy as np
import pytest
from ezdxf import recover

from tests.e2e.test_page import arc, browser, draw, open_page, server, state  # noqa: F401 - fixtures
from tests.helpers import FIXTURES

FILES = FIXTURES / "files"
PAGE = json.loads((FILES / "page-export.json").read_text())["curves"]
H = 700

pytestmark = pytest.mark.integration


def _wait_for(page, count: int) -> dict:
    """The page's state once `count` curves are read back from the service (and mixed, where they are enough)."""
    page.wait_for_function(
        f"window.curveVae.curves.length === {count} && window.curveVae.recon.every((r) => r)"
        f" && ({count} < 2 || window.curveVae.result !== null)"
    )
    return state(page)


@pytest.mark.parametrize(
    ("name", "atol"),
    [
        pytest.param("page-export.json", 0, id="json"),
        pytest.param("page-export.csv", 0, id="csv"),
        pytest.param("page-export.svg", 1e-3, id="svg"),  # the board's paths, at the 3 decimals the page writes
    ],
)
def test_the_pages_own_exports_open_where_they_were_drawn(browser, server, name, atol):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    page.set_input_files("#open-file", str(FILES / name))
    s = _wait_for(page, 3)
    assert s["mode"] == "triplet"  # A, B and C of the export (its mix is made again, not opened)
    for got, saved in zip(s["curves"], PAGE[:3]):
        np.testing.assert_allclose(got, saved["points"], atol=atol)
    assert page.locator("#hint").inner_text().startswith(f"{name}: 3 of its {3 if name.endswith('svg') else 4} curve")
    assert errors == []


def test_a_drawing_and_an_airfoil_with_notes_open_and_a_dropped_file_too(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    page.set_input_files("#open-file", str(FILES / "inkscape_drawing.svg"))
    s = _wait_for(page, 3)  # its path, polyline and polygon, fitted onto the board
    assert [len(c) for c in s["curves"]] == [120, 6, 5]
    xs = np.concatenate([np.asarray(c)[:, 0] for c in s["curves"]])
    assert xs.min() >= 0 and xs.max() <= 1000

    page.set_input_files("#open-file", str(FILES / "selig_notes.dat"))  # one curve: it replaces the oldest
    page.wait_for_function("window.curveVae.curves.length === 3 && window.curveVae.curves[2].length === 69")
    assert "selig_notes.dat:72: the coordinates end here" in page.locator("#hint").inner_text()

    text = (FILES / "page-export.csv").read_text()
    drop = page.evaluate_handle(
        """(text) => { const dt = new DataTransfer();
        dt.items.add(new File([text], "dropped.csv", { type: "text/csv" })); return dt; }""",
        text,
    )
    page.dispatch_event("#board", "drop", {"dataTransfer": drop})
    page.wait_for_function("document.getElementById('hint').textContent.startsWith('dropped.csv: 3 of its 4')")
    np.testing.assert_array_equal(state(page)["curves"][0], PAGE[0]["points"])
    assert errors == []


def test_a_file_without_curves_is_named_next_to_the_board(browser, server, tmp_path):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    (tmp_path / "latents.json").write_text('{"latents": [[0, 0]]}')
    page.set_input_files("#open-file", str(tmp_path / "latents.json"))
    page.wait_for_function("document.getElementById('board-error').textContent !== ''")
    assert page.locator("#board-error").inner_text() == 'latents.json: a JSON object needs a "curves" list'
    (tmp_path / "notes.dat").write_text("NACA 0012\n1.0 0.0\n0.5 oops\n")
    page.set_input_files("#open-file", str(tmp_path / "notes.dat"))
    page.wait_for_function("document.getElementById('board-error').textContent.includes('notes.dat:3')")
    assert state(page)["curves"] == [] and errors == []


def test_the_dxf_download_holds_the_curves_and_the_splines_exactly(browser, server, tmp_path):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    page.set_input_files("#open-file", str(FILES / "page-export.json"))
    s = _wait_for(page, 3)
    with page.expect_download() as download:
        page.click("#download-dxf")
    doc, audit = recover.readfile(download.value.path())  # ezdxf's audit, as a CAD program would check it
    assert not audit.has_errors and not audit.fixes, [e.message for e in audit.errors]
    polylines = list(doc.modelspace().query("LWPOLYLINE"))
    splines = {e.dxf.layer: e for e in doc.modelspace().query("SPLINE")}
    assert [p.dxf.layer for p in polylines] == ["input-A", "input-B", "input-C"]
    np.testing.assert_allclose([xy for xy in polylines[0].get_points("xy")], s["curves"][0], rtol=1e-12)
    assert sorted(splines) == ["interpolant", "reconstruction-A", "reconstruction-B", "reconstruction-C"]
    mix = s["result"]["spline"]
    np.testing.assert_allclose(np.asarray(splines["interpolant"].control_points)[:, :2], mix["control_points"])
    np.testing.assert_allclose(list(splines["interpolant"].knots), mix["knots"])
    assert errors == []


def _boxes(page, selector: str) -> list[dict]:
    return page.eval_on_selector_all(
        selector, "els => els.map((e) => { const b = e.getBBox(); return {x: b.x, y: b.y, w: b.width, h: b.height}; })"
    )


def _overlap(a: dict, b: dict) -> bool:
    return (
        a["x"] < b["x"] + b["w"] and b["x"] < a["x"] + a["w"] and a["y"] < b["y"] + b["h"] and b["y"] < a["y"] + a["h"]
    )


def test_names_stay_apart_and_reconstructions_show_over_the_strokes(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    page.check("#mode-triplet")
    for a0, a1 in ((0.0, 1.0), (0.0, -1.2), (0.0, 2.5)):  # three strokes from one point, as people draw them
        draw(page, arc(500 + 200 * np.cos(a0 + np.pi), 350, 200, a0 + np.pi, a0 + np.pi + a1))
    _wait_for(page, 3)
    labels = _boxes(page, "#board text.label")
    assert len(labels) == 3
    assert not any(_overlap(labels[i], labels[j]) for i in range(3) for j in range(i + 1, 3)), labels
    order = page.eval_on_selector_all("#board path", "els => els.map((e) => e.getAttribute('class'))")
    assert max(i for i, c in enumerate(order) if c == "input") < min(
        i for i, c in enumerate(order) if c == "reconstruction"
    )
    strokes = page.eval_on_selector_all("#board path.input", "els => els.map((e) => +e.getAttribute('stroke-opacity'))")
    assert all(o < 0.5 for o in strokes)  # pale bands: the dashed reconstructions on them stay in sight
    assert errors == []


def test_samples_side_by_side_and_clear_clears_everything(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    page.check("#mode-triplet")
    page.click("#sample")
    s = _wait_for(page, 3)
    boxes = [(np.min(c, axis=0), np.max(c, axis=0)) for c in map(np.asarray, s["curves"])]
    centres = [(lo + hi) / 2 for lo, hi in boxes]
    np.testing.assert_allclose([c[0] for c in centres], [1000 / 6, 500, 5000 / 6], atol=1e-6)
    assert all(boxes[i][1][0] < boxes[i + 1][0][0] for i in range(2))  # left to right, apart
    labels = _boxes(page, "#board text.label")
    assert not any(_overlap(labels[i], labels[j]) for i in range(3) for j in range(i + 1, 3))

    page.click("#vase")
    page.wait_for_function("window.curveVae.vase !== null")
    page.click("#clear")
    page.wait_for_function("window.curveVae.curves.length === 0")
    assert state(page)["vase"] is None and page.locator("#curl").inner_text() == ""
    painted = page.evaluate(
        "(() => { const c = document.getElementById('vase-view'); "
        "return c.getContext('2d').getImageData(0, 0, c.width, c.height).data.some((v) => v !== 0); })()"
    )
    assert not painted and page.locator("#board path").count() == 0
    assert errors == []


@pytest.mark.parametrize(
    "name",
    [
        "selig_notes.dat",
        "selig_two_line_header_notes.dat",
        "selig_remarks.dat",
        "lednicer_two_line_header.dat",
        "selig_fortran.dat",
        "page-export.csv",
        "page-export.json",
    ],
)
def test_the_page_reads_a_file_as_the_command_line_does(browser, server, name):  # noqa: F811
    """files.js and curve_vae/curvefiles read the same curves from the same file."""
    from curve_vae.curvefiles import read_curves

    page, errors = open_page(browser, server.url + "/")
    text = (FILES / name).read_text()
    got = page.evaluate("([name, text]) => window.curveFiles.parse(name, text).curves", [name, text])
    want = read_curves(FILES / name)
    assert len(got) == len(want)
    for g, w in zip(got, want):
        np.testing.assert_allclose(g, w, rtol=1e-15, atol=0)
    assert errors == []


@pytest.mark.parametrize(
    "text",
    [
        pytest.param("curve,x,y\nA,0,0\nA,1,1\nA,2,0\nA,3,1\nB,0,0\nB,1,1\nB,2,0\nB,3,1\nA,4,0\n", id="curve-again"),
        pytest.param("x,y,curve\n0,0,A\n1,1\n2,0,A\n3,1,A\n", id="no-name-cell"),
    ],
)
def test_the_page_refuses_a_csv_as_the_command_line_does(browser, server, text):  # noqa: F811
    """A curve's rows apart, or a row without the curve column: the same message from files.js and curvefiles."""
    from curve_vae.curvefiles import CurveFileError
    from curve_vae.curvefiles.text import parse_csv

    page, errors = open_page(browser, server.url + "/")
    got = page.evaluate(
        "(text) => { try { window.curveFiles.parse('c.csv', text); return null } catch (e) { return e.message } }", text
    )
    with pytest.raises(CurveFileError) as want:
        parse_csv(text, "c.csv")
    assert got == str(want.value) and errors == []


def test_the_page_reads_named_rows_across_blank_lines_as_the_command_line_does(browser, server):  # noqa: F811
    from curve_vae.curvefiles.text import parse_csv

    text = "curve,x,y\nA,0,0\nA,1,1\n\nA,2,0\nA,3,1\n\nB,5,5\nB,6,6\nB,7,5\nB,8,6\n"
    page, errors = open_page(browser, server.url + "/")
    got = page.evaluate("(text) => window.curveFiles.parse('c.csv', text).curves", text)
    want = parse_csv(text, "c.csv")
    assert [len(c) for c in got] == [len(c) for c in want] == [4, 4] and errors == []
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)
