"""The page with files, in Chromium against the shipped model: each of its exports (JSON, CSV, SVG, DXF) downloaded
and opened in a fresh page gives back the drawn curves and no derived curve as an input; its sheet of in-betweens,
one cell each with its weights; .npy written by numpy, the files people have (an Inkscape drawing, a DXF, an airfoil
with notes) and the page's own fixtures read by files.js as the command line reads them (curve_vae/curvefiles)."""

from __future__ import annotations

import io
import json
import re
import warnings

import numpy as np
import pytest
import svgelements as se
from ezdxf import recover

from curve_vae.curvefiles import CurveFileError, read_curves
from curve_vae.curvefiles.text import parse_csv
from tests.e2e.test_page import arc, browser, draw, open_page, server, state  # noqa: F401 - fixtures
from tests.helpers import EXPORT_TOLERANCE, FIXTURES, ROOT

FILES = FIXTURES / "files"
FILES_JS = [ROOT / "service" / "static" / name for name in ("files.js", "files-drawings.js")]  # the readers
FORMATS = ("json", "csv", "svg", "dxf")

pytestmark = pytest.mark.integration


def _ready(page, count: int) -> dict:
    """The page's state once `count` curves are reconstructed, mixed and swept."""
    page.wait_for_function(
        f"window.curveVae.curves.length === {count} && window.curveVae.recon.length === {count}"
        " && window.curveVae.recon.every((r) => r) && window.curveVae.result !== null"
        " && window.curveVae.strip.length > 0"
    )
    return state(page)


def _quiet(fn, *args):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*args)


@pytest.fixture(scope="module")
def exported(browser, server, tmp_path_factory):  # noqa: F811
    """Two strokes drawn on the page, and what each of its export buttons (found by their text) downloads."""
    page, errors = open_page(browser, server.url + "/")
    draw(page, arc(500, 420, 250, np.pi, 2 * np.pi, n=24))  # a bowl
    draw(page, arc(500, 250, 220, 0.9 * np.pi, 0.1 * np.pi, n=24))  # a hump
    drawn = _ready(page, 2)
    folder = tmp_path_factory.mktemp("exports")
    files = {}
    for kind, text in [*((f, f.upper()) for f in FORMATS), ("sheet", "Sweep sheet")]:
        with page.expect_download() as download:
            page.get_by_role("button", name=text, exact=True).click()
        files[kind] = folder / download.value.suggested_filename
        download.value.save_as(files[kind])
    page.context.close()
    assert errors == []
    return drawn, files


@pytest.mark.parametrize(("kind", "rtol"), list(EXPORT_TOLERANCE.items()), ids=list(EXPORT_TOLERANCE))
def test_each_export_reopens_into_the_drawn_curves(browser, server, exported, kind, rtol):  # noqa: F811
    drawn, files = exported
    page, errors = open_page(browser, server.url + "/")
    page.set_input_files("#open-file", str(files[kind]))
    s = _ready(page, 2)
    assert s["mode"] == "pair" and len(s["curves"]) == 2  # the inputs: no reconstruction or in-between made a curve
    for got, want in zip(s["curves"], drawn["curves"]):
        np.testing.assert_allclose(got, want, rtol=rtol, atol=1e-9)
    assert errors == []


def test_what_each_export_holds_and_how_the_command_line_reads_it(browser, exported):  # noqa: F811
    """The same curves with the same names and roles in every export; the command line reads the same inputs."""
    drawn, files = exported
    saved = json.loads(files["json"].read_text())["curves"]
    names = [c["name"] for c in saved]
    assert names[:2] == ["A", "B"] and {"A reconstructed", "B reconstructed", "mix"} <= set(names)
    assert [c["role"] for c in saved].count("input") == 2
    assert all(c["role"] == "interpolant" and c["weights"] for c in saved if c["name"] not in names[:2] + names[2:4])
    rows = files["csv"].read_text().splitlines()
    assert rows[0] == "curve,role,of,weights,index,x,y"
    assert len(rows) == 1 + sum(len(c["points"]) for c in saved)
    paths = [e.values["attributes"] for e in se.SVG.parse(str(files["svg"])).elements() if isinstance(e, se.Path)]
    assert sorted(p["data-name"] for p in paths) == sorted(names)
    doc, audit = recover.readfile(files["dxf"])  # ezdxf's audit, as a CAD program would check it
    assert not audit.has_errors and not audit.fixes, [e.message for e in audit.errors]
    assert len(doc.modelspace()) == len(saved)
    for c, e in zip(saved, doc.modelspace()):
        assert e.dxftype() == ("SPLINE" if "spline" in c else "LWPOLYLINE")
        if "spline" in c:  # the B-spline exactly: its control points and knots
            np.testing.assert_array_equal(np.asarray(e.control_points)[:, :2], c["spline"]["control_points"])
            np.testing.assert_array_equal(list(e.knots), c["spline"]["knots"])
    for kind in FORMATS:
        curves = _quiet(read_curves, files[kind])
        assert len(curves) == 2
        np.testing.assert_allclose(curves[0], drawn["curves"][0], rtol=1e-9)


def test_the_sheet_holds_one_cell_per_in_between_with_its_weights(browser, exported):  # noqa: F811
    drawn, files = exported
    text = files["sheet"].read_text()
    svg = se.SVG.parse(io.StringIO(text))
    paths = [e.values["attributes"] for e in svg.elements() if isinstance(e, se.Path)]
    labels = [e.text for e in svg.elements() if isinstance(e, se.Text)]
    assert len(paths) == len(labels) == len(drawn["strip"]) > 1
    assert {p["class"] for p in paths} == {"interpolant"}
    for p, label, w in zip(paths, labels, drawn["stripWeights"]):
        weights = dict((k, float(v)) for k, v in (t.split("=") for t in p["data-weights"].split()))
        np.testing.assert_allclose([weights["A"], weights["B"]], w, atol=1e-12)
        shown = dict((k, float(v)) for v, k in re.findall(r"([\d.]+) ([ABC])", label))
        np.testing.assert_allclose([shown.get("A", 0), shown.get("B", 0)], w, atol=5e-4)
    cells = {(round(float(g)), round(float(h))) for g, h in re.findall(r"translate\(([-\d.]+),([-\d.]+)\) scale", text)}
    assert len(cells) == len(paths)  # each in its own cell
    assert len(read_curves(files["sheet"])) == len(paths)  # no input in it: every in-between is read


# ------------------------------------------------------------------------------------ files.js as the CLI reads


@pytest.fixture(scope="module")
def files_page(browser):  # noqa: F811
    """A blank page with the readers (files.js, files-drawings.js), and the errors it raises."""
    page = browser.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.set_content("<!doctype html><html><body></body></html>")
    for script in FILES_JS:
        page.add_script_tag(path=str(script))
    yield page, errors
    page.close()


def _parse(page, name: str, data: str | bytes) -> dict:
    if isinstance(data, bytes):
        return page.evaluate(
            "([name, bytes]) => window.curveFiles.parse(name, Uint8Array.from(bytes).buffer)", [name, list(data)]
        )
    return page.evaluate("([name, text]) => window.curveFiles.parse(name, text)", [name, data])


def _refusal(page, name: str, data: str | bytes) -> str:
    arg = list(data) if isinstance(data, bytes) else data
    return page.evaluate(
        """([name, data]) => { try { window.curveFiles.parse(name, typeof data === "string" ? data
          : Uint8Array.from(data).buffer); return null } catch (e) { return e.message } }""",
        [name, arg],
    )


@pytest.mark.parametrize(
    ("name", "rtol"),
    [
        ("selig_notes.dat", 1e-15),
        ("selig_two_line_header_notes.dat", 1e-15),
        ("selig_remarks.dat", 1e-15),
        ("lednicer_two_line_header.dat", 1e-15),
        ("selig_fortran.dat", 1e-15),
        ("page-export.csv", 0),
        ("page-export.json", 0),
        ("page-export.svg", 1e-15),
        ("page-export.dxf", 0),
        ("page-sheet.svg", 1e-12),  # its cells' transforms, applied by each in its own order
        ("inkscape_drawing.svg", 1e-12),
        ("ezdxf_drawing.dxf", 1e-9),
    ],
)
def test_the_page_reads_a_file_as_the_command_line_does(files_page, name, rtol):
    """files.js and curve_vae/curvefiles read the same curves from the same file, and say the same of derived ones."""
    page, errors = files_page
    got = _parse(page, name, (FILES / name).read_text(encoding="latin-1"))
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        want = read_curves(FILES / name)
    assert len(got["curves"]) == len(want)
    for g, w in zip(got["curves"], want):
        np.testing.assert_allclose(g, w, rtol=rtol, atol=1e-9 if rtol else 0)
    derived = [str(w.message) for w in said if "derived" in str(w.message)]
    assert [n for n in got["notes"] if "derived" in n] == [d.replace(str(FILES / name), name) for d in derived]
    assert errors == []


def test_derived_curves_come_back_apart_with_their_names_roles_and_weights(files_page):
    page, errors = files_page
    saved = json.loads((FILES / "page-export.json").read_text())["curves"]
    for kind in FORMATS:
        read = _parse(page, f"page-export.{kind}", (FILES / f"page-export.{kind}").read_text())
        derived = sorted(read["derived"], key=lambda d: [c["name"] for c in saved].index(d["name"]))
        assert [(d["name"], d["role"], d.get("of"), d.get("weights")) for d in derived] == [
            (c["name"], c["role"], c.get("of"), c.get("weights")) for c in saved if c["role"] != "input"
        ], kind
        splines = [d for d in derived if "spline" in d]
        if kind in ("json", "dxf"):  # the formats that hold a B-spline exactly
            keys = ("degree", "knots", "control_points")
            assert [[d["spline"][k] for k in keys] for d in splines] == [
                [c["spline"][k] for k in keys] for c in saved if "spline" in c
            ]
    assert errors == []


def _npy(array: np.ndarray, version: tuple[int, int] | None = None) -> bytes:
    out = io.BytesIO()
    np.lib.format.write_array(out, array, version=version)
    return out.getvalue()


CURVES = np.stack([arc(500, 350, 200 + 30 * i, 0, np.pi, n=40) for i in range(3)])


@pytest.mark.parametrize(
    "array",
    [
        pytest.param(_npy(CURVES.astype(np.float32)), id="float32-many"),
        pytest.param(_npy(CURVES[0]), id="float64-one"),
        pytest.param(_npy(CURVES.round().astype(np.int32)), id="int32"),
        pytest.param(_npy(CURVES.round().astype(np.int64)), id="int64"),
        pytest.param(_npy(CURVES.astype(">f8")), id="big-endian"),
        pytest.param(_npy(np.asfortranarray(CURVES[0])), id="fortran-order"),
        pytest.param(_npy(CURVES, version=(2, 0)), id="version-2"),
        pytest.param(_npy(CURVES, version=(3, 0)), id="version-3"),
    ],
)
def test_npy_reads_as_the_command_line_reads_it(files_page, tmp_path, array):
    page, errors = files_page
    (tmp_path / "c.npy").write_bytes(array)
    got = _parse(page, "c.npy", array)["curves"]
    want = read_curves(tmp_path / "c.npy")
    assert len(got) == len(want)
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)
    assert errors == []


@pytest.mark.parametrize(
    ("name", "data", "says"),
    [
        pytest.param(
            "c.npy", _npy(np.zeros((3, 4))), "c.npy: an array of shape (3, 4); curves are (n, 2) or (N, n, 2)"
        ),
        pytest.param("c.npy", _npy(np.zeros(5)), "c.npy: an array of shape (5,); curves are (n, 2) or (N, n, 2)"),
        pytest.param("c.npy", _npy(np.zeros((4, 2), np.complex64)), "c.npy: an array of <c8; curves are numbers"),
        pytest.param("c.npy", b"PK\x03\x04 not numpy", "c.npy: not a numpy file"),
        pytest.param("c.npz", b"PK\x03\x04", "c.npz: the page opens .npy, not .npz: save the curves as one array with"),
    ],
)
def test_npy_that_is_not_curves_is_refused_clearly(files_page, tmp_path, name, data, says):
    page, errors = files_page
    assert (_refusal(page, name, data) or "").startswith(says)
    if name.endswith(".npy") and "<c8" not in says:
        (tmp_path / name).write_bytes(data)
        with pytest.raises(CurveFileError, match=re.escape(says.split(";")[0])):
            read_curves(tmp_path / name)
    assert errors == []


def test_an_npy_opens_on_the_page(browser, server, tmp_path):  # noqa: F811
    """Three curves of numpy's, picked: triplet mode, the curves as the command line reads them (on the board)."""
    np.save(tmp_path / "arcs.npy", CURVES)
    page, errors = open_page(browser, server.url + "/")
    page.set_input_files("#open-file", str(tmp_path / "arcs.npy"))
    s = _ready(page, 3)
    assert s["mode"] == "triplet"
    np.testing.assert_array_equal(s["curves"], read_curves(tmp_path / "arcs.npy"))
    assert errors == []


def test_an_svg_arc_and_transforms_read_as_the_command_line_reads_them(files_page, tmp_path):
    """Every kind of segment and transform, and a <use>. (An arc is sampled by its angle: under a transform that
    stretches it unevenly, svgelements takes other angles than the arc's own, so the arc here is turned and scaled
    evenly.)"""
    page, errors = files_page
    text = (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="-50 -50 200 200" width="400" height="400">'
        '<g transform="translate(10,5) rotate(30) scale(2)"><path d="M0 0 a 10 20 30 0 1 15 5 l 5 15 '
        'q 10 -10 20 0 t 20 0 h 5 v 5 Z"/></g>'
        '<path transform="scale(2,1.5) skewY(5)" d="M0,0 C 10,10 20,-10 30,0 S 50,10 60,0"/>'
        '<defs><path id="p" d="M0,0 L1,1 L2,0 L3,1"/></defs><use href="#p" x="7" y="3" transform="skewX(10)"/>'
        '<polygon points="0,0 10,0 10,10 0,10" transform="matrix(1 0.2 0.1 1 3 4)"/></svg>'
    )
    got = _parse(page, "d.svg", text)["curves"]
    (tmp_path / "d.svg").write_text(text)
    want = read_curves(tmp_path / "d.svg")
    assert [len(c) for c in got] == [len(c) for c in want] == [1 + 16 + 1 + 32 + 1 + 1 + 1, 1 + 32, 4, 5]
    for g, w in zip(got, want):
        np.testing.assert_allclose(g, w, rtol=1e-9, atol=1e-9)
    assert errors == []


def test_a_csv_refusal_is_the_command_lines(files_page):
    """A curve's rows apart, or a row without the curve column: the same message from files.js and curvefiles."""
    page, errors = files_page
    for text in (
        "curve,x,y\nA,0,0\nA,1,1\nA,2,0\nA,3,1\nB,0,0\nB,1,1\nB,2,0\nB,3,1\nA,4,0\n",
        "x,y,curve\n0,0,A\n1,1\n2,0,A\n3,1,A\n",
    ):
        with pytest.raises(CurveFileError) as want:
            parse_csv(text, "c.csv")
        assert _refusal(page, "c.csv", text) == str(want.value)
    text = "curve,x,y\nA,0,0\nA,1,1\n\nA,2,0\nA,3,1\n\nB,5,5\nB,6,6\nB,7,5\nB,8,6\n"
    assert _parse(page, "c.csv", text)["curves"] == [c.tolist() for c in parse_csv(text, "c.csv")]
    assert errors == []


def test_a_drawing_an_airfoil_and_a_dropped_file_open_on_the_page(browser, server):  # noqa: F811
    page, errors = open_page(browser, server.url + "/")
    page.set_input_files("#open-file", str(FILES / "inkscape_drawing.svg"))
    s = _ready(page, 3)  # its path, polyline and polygon, fitted onto the board
    assert [len(c) for c in s["curves"]] == [33, 6, 5]
    xs = np.concatenate([np.asarray(c)[:, 0] for c in s["curves"]])
    assert xs.min() >= 0 and xs.max() <= 1000

    page.set_input_files("#open-file", str(FILES / "selig_notes.dat"))  # one curve: a fourth, D
    page.wait_for_function("window.curveVae.curves.length === 4 && window.curveVae.curves[3].length === 69")
    assert state(page)["names"] == ["A", "B", "C", "D"]

    text = (FILES / "page-export.csv").read_text()
    drop = page.evaluate_handle(
        """(text) => { const dt = new DataTransfer();
        dt.items.add(new File([text], "dropped.csv", { type: "text/csv" })); return dt; }""",
        text,
    )
    page.dispatch_event("#board", "drop", {"dataTransfer": drop})
    saved = json.loads((FILES / "page-export.json").read_text())["curves"]
    page.wait_for_function("document.getElementById('hint').textContent.startsWith('dropped.csv: its 3 curve')")
    got = state(page)["curves"]
    assert len(got) == 7 and state(page)["names"][4:] == ["E", "F", "G"]  # added, none dropped
    for g, c in zip(got[4:], saved[:3]):
        np.testing.assert_array_equal(g, c["points"])
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
    _ready(page, 3)
    labels = _boxes(page, "#board text.label")
    assert len(labels) >= 3  # A, B, C (and the mix's)
    n = len(labels)
    assert not any(_overlap(labels[i], labels[j]) for i in range(n) for j in range(i + 1, n)), labels
    order = page.eval_on_selector_all("#board path", "els => els.map((e) => e.getAttribute('class').split(' ')[0])")
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
    s = _ready(page, 3)
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
