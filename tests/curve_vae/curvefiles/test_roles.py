"""curve_vae.curvefiles.roles: one rule for what a file's curves are, in every format. The page's exports (JSON, CSV,
SVG, DXF) give the drawing's inputs, the same curves from each; a file that marks roles but holds no input (the
command line's own reconstructions) gives them all; a file without roles is read whole. The command line's drawings
say each curve's role, name, input and weights as the page's do."""

from __future__ import annotations

import json

import ezdxf
import numpy as np
import pytest
import svgelements as se
from ezdxf import recover

from curve_vae.curvefiles import CurveFileWarning, read_curves, write_output
from curve_vae.curvefiles.dxf import layer_name
from curve_vae.curvefiles.roles import Found, role_of, the_inputs
from tests.helpers import EXPORT_TOLERANCE, FIXTURES

FILES = FIXTURES / "files"
PAGE = json.loads((FILES / "page-export.json").read_text())["curves"]
INPUTS = [c for c in PAGE if c["role"] == "input"]
SQUARE_WAVE = [[0, 0], [1, 1], [2, 0], [3, 1]]


@pytest.mark.parametrize(
    ("name", "rtol"), [pytest.param(f"page-export.{kind}", rtol, id=kind) for kind, rtol in EXPORT_TOLERANCE.items()]
)
def test_each_of_the_pages_exports_gives_the_drawings_inputs(name, rtol):
    derived = len(PAGE) - len(INPUTS)
    assert 2 <= len(INPUTS) <= 3 and derived > 0  # the fixture holds reconstructions and interpolants too
    with pytest.warns(CurveFileWarning, match=rf"its {len(INPUTS)} input curve\(s\) read; {derived} derived curve"):
        curves = read_curves(FILES / name)
    assert len(curves) == len(INPUTS)
    for got, saved in zip(curves, INPUTS):
        np.testing.assert_allclose(got, saved["points"], rtol=rtol, atol=1e-12)


def test_the_pages_exports_name_each_curve_and_its_role_alike():
    """Names, roles, inputs and weights: the JSON's fields, the CSV's columns, the SVG's attributes, the DXF's XDATA."""
    want = [(c["name"], c["role"], c.get("of", ""), c.get("weights") or {}) for c in PAGE]
    rows = [r.split(",") for r in (FILES / "page-export.csv").read_text().splitlines()]
    assert rows[0] == ["curve", "role", "of", "weights", "index", "x", "y"]
    firsts = [r for r in rows[1:] if r[4] == "0"]
    weights = [dict((k, float(v)) for k, v in (w.split("=") for w in r[3].split())) for r in firsts]
    assert [(r[0], r[1], r[2], w) for r, w in zip(firsts, weights)] == want
    paths = [e for e in se.SVG.parse(str(FILES / "page-export.svg")).elements() if isinstance(e, se.Path)]
    attrs = [e.values["attributes"] for e in paths]
    assert sorted((a["data-name"], a["class"], a.get("data-of", "")) for a in attrs) == sorted(w[:3] for w in want)
    doc, audit = recover.readfile(FILES / "page-export.dxf")
    assert not audit.has_errors and not audit.fixes, [e.message for e in audit.errors]
    marks = [dict(str(t.value).split("=", 1) for t in e.get_xdata("CURVE_VAE")) for e in doc.modelspace()]
    assert [(m["name"], m["role"], m.get("of", "")) for m in marks] == [w[:3] for w in want]
    assert [e.dxf.layer for e in doc.modelspace()] == [layer_name(c) for c in PAGE]


@pytest.mark.parametrize("suffix", [".svg", ".dxf", ".csv"])
def test_a_file_of_reconstructions_only_gives_them_all(tmp_path, suffix):
    """The command line's own output, marked: no input in it, so every curve is read, no warning."""
    curves = [np.asarray(SQUARE_WAVE, float) + i for i in range(3)]
    marks = [{"name": f"{n} reconstructed", "role": "reconstruction", "of": n} for n in "ABC"]
    out = tmp_path / f"rec{suffix}"
    write_output(str(out), {"curves": [c.tolist() for c in curves]}, marks=marks)
    back = read_curves(out)
    assert len(back) == 3
    for got, want in zip(back, curves):
        np.testing.assert_allclose(got, want, atol=1e-12)


@pytest.mark.parametrize("suffix", [".svg", ".dxf", ".csv"])
def test_the_command_lines_drawing_with_marks_reads_back_its_inputs(tmp_path, suffix):
    curves = [np.asarray(SQUARE_WAVE, float) + i for i in range(4)]
    marks = [
        {"name": "A", "role": "input"},
        {"name": "B", "role": "input"},
        {"name": "A reconstructed", "role": "reconstruction", "of": "A"},
        {"name": "mix", "role": "interpolant", "weights": {"A": 0.75, "B": 0.25}},
    ]
    out = tmp_path / f"drawing{suffix}"
    write_output(str(out), {"curves": [c.tolist() for c in curves]}, marks=marks)
    with pytest.warns(CurveFileWarning, match=r"its 2 input curve\(s\) read; 2 derived curve\(s\)"):
        a, b = read_curves(out)
    np.testing.assert_allclose([a, b], curves[:2], atol=1e-12)
    text = out.read_text()
    if suffix == ".svg":
        assert 'class="interpolant" data-name="mix" data-weights="A=0.75 B=0.25" stroke="#d62728"' in text
        assert 'class="reconstruction" data-name="A reconstructed" data-of="A" stroke="#1f77b4" stroke-dash' in text
    elif suffix == ".csv":
        assert text.splitlines()[-1] == "mix,interpolant,,A=0.75 B=0.25,3,6.0,4.0"


def test_a_layer_names_role_and_curve_without_what_autocad_refuses(tmp_path):
    mark = {"name": 'a<b>/c\\d"e:f;g?h*i|j,k=l`m', "role": "interpolant", "weights": {"A": 0.5, "B": 0.5}}
    assert layer_name(mark) == "interpolant-a_b__c_d_e_f_g_h_i_j_k_l_m"
    out = tmp_path / "odd.dxf"
    write_output(str(out), {"curves": [SQUARE_WAVE]}, marks=[mark])
    (e,) = ezdxf.readfile(out).modelspace()
    assert e.dxf.layer == layer_name(mark)
    assert [t.value for t in e.get_xdata("CURVE_VAE")] == [
        "role=interpolant",
        f"name={mark['name']}",
        "weights=A=0.5 B=0.5",
    ]


def test_a_dxf_layer_alone_marks_the_role(tmp_path):
    """A drawing made elsewhere, its layers named as the page names them and no XDATA: the layers say the roles."""
    doc = ezdxf.new()
    for i, layer in enumerate(["input-A", "reconstruction-A", "interpolant"]):
        doc.modelspace().add_lwpolyline(np.asarray(SQUARE_WAVE, float) + i, dxfattribs={"layer": layer})
    doc.saveas(tmp_path / "layers.dxf")
    with pytest.warns(CurveFileWarning, match=r"its 1 input curve\(s\) read; 2 derived"):
        (curve,) = read_curves(tmp_path / "layers.dxf")
    np.testing.assert_array_equal(curve, SQUARE_WAVE)


@pytest.mark.parametrize(
    ("found", "kept"),
    [
        pytest.param([None, None], [0, 1], id="no-roles"),
        pytest.param(["input", "reconstruction", "input", "interpolant"], [0, 2], id="inputs"),
        pytest.param(["reconstruction", "interpolant"], [0, 1], id="no-input"),
        pytest.param(["input", None, "sample"], [0], id="unmarked-beside-inputs"),
    ],
)
def test_the_rule(found, kept, recwarn):
    got = the_inputs([Found(str(i), SQUARE_WAVE, r) for i, r in enumerate(found)], "f")
    assert [int(f.label) for f in got] == kept
    assert len(recwarn) == (len(kept) < len(found))


@pytest.mark.parametrize(
    ("marks", "role"),
    [("input", "input"), ("curve interpolant", "interpolant"), ("st0", None), ("", None), (None, None)],
)
def test_an_svg_class_names_the_role_among_its_words(marks, role):
    assert role_of(marks) == role


def test_names_run_a_to_z_then_aa_and_back():
    from curve_vae.curvefiles.roles import curve_name, name_index

    assert [curve_name(k) for k in (0, 1, 25, 26, 27, 51, 52, 701, 702)] == [
        "A", "B", "Z", "AA", "AB", "AZ", "BA", "ZZ", "AAA"
    ]  # fmt: skip
    assert all(name_index(curve_name(k)) == k for k in range(1000))
    assert name_index("mix") is None and name_index("A reconstructed") is None


def test_the_pages_palette_and_names_are_the_command_lines():
    """The page names and colours curves as curvefiles.roles does (service/static/files.js): the same list, the same
    order; its DXF writer's colour indices are roles.PALETTE_ACI."""
    import re

    from curve_vae.curvefiles.roles import PALETTE, PALETTE_ACI
    from tests.helpers import ROOT

    static = ROOT / "service" / "static"
    js = (static / "files.js").read_text()
    page_palette = re.search(r"const PALETTE = \[([^\]]*)\]", js)
    assert page_palette is not None
    assert tuple(re.findall(r'"(#[0-9a-f]{6})"', page_palette.group(1))) == PALETTE
    aci = re.search(r"const PALETTE_ACI = \[([^\]]*)\]", (static / "files-out.js").read_text())
    assert aci is not None and tuple(int(v) for v in aci.group(1).split(",")) == PALETTE_ACI
    assert len(PALETTE_ACI) == len(PALETTE)
