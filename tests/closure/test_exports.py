"""``hfgpu export``: StimPlan XML parsed back the way ResInsight's RifStimPlanXmlReader reads it, VTK files and
CSV tables read back, all checked against the results file; ``/closure`` written by a real run; plot maps."""

import base64
import csv
import math
import re
import xml.etree.ElementTree as ET

import h5py
import numpy as np
import pytest
from closure_fakes import FRAME, NX, NZ, box_text, cell_centres, parcels, snapshot, write_results

import hfgpu
from hfgpu.cli import main
from hfgpu.closure.conductivity import closure_of
from hfgpu.io.export import export
from hfgpu.units import convert

INLET = '[[geometry.inlets]]\nkind = "point"\nx = "2.5 cm"\ndepth = "1.5 cm"\n'


@pytest.fixture(scope="module")
def results_path(tmp_path_factory):
    """A proppant-only results file: two snapshots, the last a pack propping the lower half of the box."""
    x, z = cell_centres()
    d = 300e-6
    n = np.where(z > 0.02, 0.6 * 0.004 * FRAME.dx * FRAME.dz / (math.pi / 6 * d**3), 10.0)
    snaps = [snapshot(parcels(x, z, d, n, moving=True), time=0.5), snapshot(parcels(x, z, d, n), time=1.0)]
    for k, snap in enumerate(snaps):
        snap.grid["pressure"][:] = 1e5 * (k + 1) * (1 + np.arange(NX))
    path = tmp_path_factory.mktemp("export") / "r.h5"
    scene = box_text('[closure]\nsettling = "in_place"\nclosure_stress = "3000 psi"')
    write_results(path, scene.replace("[[proppant]]", INLET + "[[proppant]]"), snaps)
    return path


def _numbers(text: str) -> list[float]:
    """As RifStimPlanXmlReader::getGriddingValues: brackets and line breaks to spaces, split on blanks."""
    return [float(v) for v in text.replace("\n", " ").replace("[", " ").replace("]", " ").split()]


def read_stimplan(path) -> dict:
    """The file read with the reader's layout: grid (uom, xs, ys reversed and negated), perf depths, and per
    property (name, uom) the rows of each time step, one row per <depth>, read from the element after it."""
    root = ET.parse(path).getroot()
    assert root.tag == "contours"
    grid = root.find("grid")
    out = {"uom": grid.get("uom"), "xs": _numbers(grid.find("xs").text),
           "ys": [-y for y in reversed(_numbers(grid.find("ys").text))],
           "xCount": int(grid.get("xCount")), "yCount": int(grid.get("yCount")),
           "topTVD": float(root.find("perf/topTVD").text), "bottomTVD": float(root.find("perf/bottomTVD").text),
           "properties": {}}
    for prop in root.find("properties"):
        for time in prop.findall("time"):
            children = list(time)
            depths = [float(c.text) for c in children if c.tag == "depth"]
            rows = [_numbers(c.text) for c in children if c.tag == "data"]
            assert [c.tag for c in children] == ["depth", "data"] * len(depths)
            out["properties"][(prop.get("name"), prop.get("uom"))] = (float(time.get("value")), depths, rows)
    return out


@pytest.mark.parametrize("units", ["SI", "field"])
def test_stimplan_xml_parses_back_as_resinsight_reads_it(results_path, tmp_path, units):
    out = tmp_path / "frac.xml"
    assert export(results_path, "stimplan-xml", out, units) == [out]
    text = out.read_text()
    assert re.search(r"</depth>\n\s*<data>", text) and not re.search(r"</depth><data>", text)
    data = read_stimplan(out)
    length, width_unit, conductivity_unit, pint_unit = (("m", "cm", "md-m", "md*m") if units == "SI"
                                                         else ("ft", "in", "md-ft", "md*ft"))
    to_length = convert(1, "m", length)
    closure = closure_of(hfgpu.open_results(results_path))
    x, z = closure.frame.centres(NZ, NX)
    assert data["uom"] == length and data["xCount"] == NX and data["yCount"] == NZ
    np.testing.assert_allclose(data["xs"], (x - 0.025) * to_length, rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(data["ys"], -z * to_length, rtol=1e-7)   # the reader's m_Ys: -depth, row order
    assert data["topTVD"] == data["bottomTVD"] == pytest.approx(0.015 * to_length, rel=1e-7)
    expected = {("WIDTH", width_unit): closure.fields["propped_width"] * convert(1, "m", width_unit),
                ("CONDUCTIVITY", conductivity_unit): closure.fields["conductivity"] * convert(1, "m**3", pint_unit),
                ("PERMEABILITY", "md"): closure.fields["permeability"] * convert(1, "m**2", "md")}
    assert set(data["properties"]) == set(expected)
    for key, values in expected.items():
        minutes, depths, rows = data["properties"][key]
        assert minutes == pytest.approx(1.0 / 60.0)
        np.testing.assert_allclose(depths, z * to_length, rtol=1e-7)
        np.testing.assert_allclose(rows, values, rtol=1e-7)
    assert np.count_nonzero(expected[("CONDUCTIVITY", conductivity_unit)]) == NX * NZ // 2


def _vtk_arrays(path) -> dict:
    """name -> values of the DataArrays of a VTK XML file (inline binary, UInt64 header)."""
    out = {}
    for array in ET.parse(path).getroot().iter("DataArray"):
        raw = base64.b64decode(array.text)
        size = int(np.frombuffer(raw[:8], "<u8")[0])
        dtype = {"Float64": "<f8", "Int64": "<i8", "UInt8": "u1", "UInt64": "<u8"}[array.get("type")]
        assert size == len(raw) - 8
        out[array.get("Name")] = np.frombuffer(raw[8:], dtype)
    return out


def test_vtk_series_read_back(results_path, tmp_path):
    written = export(results_path, "vtk", tmp_path / "series.pvd")
    names = sorted(p.name for p in written)
    assert names == ["series_closure.vti", "series_parcels.pvd", "series_proppant.pvd"]
    results = hfgpu.open_results(results_path)
    collection = ET.parse(tmp_path / "series_proppant.pvd").getroot()
    assert collection.get("type") == "Collection"
    entries = collection.findall("Collection/DataSet")
    np.testing.assert_allclose([float(e.get("timestep")) for e in entries], results.proppant_snapshots.times)
    for entry, snap in zip(entries, results.proppant_snapshots):
        piece = tmp_path / entry.get("file")
        image = ET.parse(piece).getroot().find("ImageData")
        assert image.get("WholeExtent") == f"0 {NX} 0 {NZ} 0 0"
        origin = [float(v) for v in image.get("Origin").split()]
        assert origin[:2] == pytest.approx([0.0, -NZ * FRAME.dz])
        arrays = _vtk_arrays(piece)
        for name in ("pressure", "width", "volume_fraction"):
            np.testing.assert_array_equal(arrays[name].reshape(NZ, NX)[::-1], snap.grid[name])
    parcels_entries = ET.parse(tmp_path / "series_parcels.pvd").getroot().findall("Collection/DataSet")
    last = results.proppant_snapshots[-1]
    arrays = _vtk_arrays(tmp_path / parcels_entries[-1].get("file"))
    points = arrays["points"].reshape(-1, 3)
    np.testing.assert_array_equal(points[:, 0], last.parcels["x"])
    np.testing.assert_array_equal(points[:, 1], -last.parcels["z"])
    np.testing.assert_array_equal(arrays["radius"], last.parcels["radius"])
    np.testing.assert_array_equal(arrays["offsets"], np.arange(1, points.shape[0] + 1))
    closure = closure_of(results)
    arrays = _vtk_arrays(tmp_path / "series_closure.vti")
    np.testing.assert_array_equal(arrays["conductivity"].reshape(NZ, NX)[::-1], closure.fields["conductivity"])


def test_vtk_library_reads_the_files(results_path, tmp_path):
    """Where the VTK package is installed (not a dependency), its own XML readers open the pieces."""
    pytest.importorskip("vtkmodules")
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPolyDataReader

    export(results_path, "vtk", tmp_path / "s")
    reader = vtkXMLImageDataReader()
    reader.SetFileName(str(tmp_path / "s_closure.vti"))
    reader.Update()
    values = vtk_to_numpy(reader.GetOutput().GetCellData().GetArray("propped_width"))
    expected = closure_of(hfgpu.open_results(results_path)).fields["propped_width"]
    np.testing.assert_array_equal(values.reshape(NZ, NX)[::-1], expected)
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / "s_vtk" / "parcels_000001.vtp"))
    reader.Update()
    assert reader.GetOutput().GetNumberOfVerts() == NX * NZ


def _read_csv(path) -> tuple[list[str], np.ndarray]:
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.parametrize("units", ["SI", "field"])
def test_csv_tables_read_back(results_path, tmp_path, units):
    out = tmp_path / "map.csv"
    assert export(results_path, "csv", out, units) == [out, tmp_path / "map_pressure.csv"]
    results = hfgpu.open_results(results_path)
    closure = closure_of(results)
    header, table = _read_csv(out)
    conductivity_unit = "m^3" if units == "SI" else "md ft"
    assert header[:4] == [f"x [{'m' if units == 'SI' else 'ft'}]", f"depth [{'m' if units == 'SI' else 'ft'}]",
                          "propped", f"propped_width [{'m' if units == 'SI' else 'in'}]"]
    assert header[4] == f"conductivity [{conductivity_unit}]"
    to = convert(1, "m**3", "md*ft") if units == "field" else 1.0
    np.testing.assert_allclose(table[:, 4], closure.fields["conductivity"].ravel() * to, rtol=1e-9)
    np.testing.assert_array_equal(table[:, 2], closure.fields["propped"].ravel())
    stress = convert(1, "Pa", "psi") if units == "field" else 1.0
    np.testing.assert_allclose(table[:, 6], 3000 * 6894.757293168361 * stress, rtol=1e-9)
    header, history = _read_csv(tmp_path / "map_pressure.csv")
    assert header[0] == "time [s]" and header[1] == f"pressure_injection [{'Pa' if units == 'SI' else 'psi'}]"
    np.testing.assert_allclose(history[:, 0], results.proppant_snapshots.times)
    p = 1.0 if units == "SI" else convert(1, "Pa", "psi")
    for row, snap in zip(history, results.proppant_snapshots):
        # the inlet at x = 2.5 cm lies in column 2 (centres 0.5, 1.5, 2.5 cm ...)
        np.testing.assert_allclose(row[1:], np.array([snap.grid["pressure"][1, 2], snap.grid["pressure"].mean(),
                                                      snap.grid["pressure"].max()]) * p, rtol=1e-9)


def test_cli_export_and_errors(results_path, tmp_path, capsys):
    assert main(["export", str(results_path), "--format", "csv", "--out", str(tmp_path / "m.csv")]) == 0
    assert capsys.readouterr().out.split() == [str(tmp_path / "m.csv"), str(tmp_path / "m_pressure.csv")]
    assert main(["export", str(tmp_path / "missing.h5"), "--format", "csv", "--out", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("hfgpu export: error: cannot open results file") and err.count("\n") == 1
    assert main(["export", str(results_path), "--format", "vtk", "--out", str(tmp_path / "no" / "x")]) == 2
    assert "does not exist" in capsys.readouterr().err
    with pytest.raises(SystemExit) as info:
        main(["export", str(results_path), "--format", "shapefile", "--out", "x"])
    assert info.value.code == 2


RUN_SCENE = """
[run]
end_time = "0.02 s"
physics = ["proppant"]
[fluid]
viscosity = "1 cP"
[mesh]
cell_size = "2 mm"
[output]
every = "0.01 s"
units = "field"
[geometry]
kind = "box"
length = "1 cm"
height = "2 cm"
width = "2 mm"
[[proppant]]
name = "sand"
density = "2650 kg/m**3"
diameter = "200 um"
initial_volume_fraction = 0.1
[mppic]
backend = "numpy"
parcels_per_cell = 4
[closure]
formation_permeability = "0.01 md"
"""


def test_run_writes_closure_and_plots_its_maps(tmp_path, capsys):
    out = tmp_path / "run.h5"
    summary = hfgpu.run(hfgpu.load_scene(RUN_SCENE), out, progress=True)
    printed = capsys.readouterr().out
    assert "mean conductivity" in printed and "md ft" in printed
    results = hfgpu.open_results(out)
    stored = results.closure
    assert stored is not None and stored["attrs"]["settling"] == "bed"
    with h5py.File(out, "r") as f:
        assert f["closure"].attrs["dx"] == 0.002
        for name, unit in (("propped_width", "m"), ("conductivity", "m^3"), ("closure_stress", "Pa"),
                           ("permeability", "m^2")):
            assert f[f"closure/{name}"].shape == (10, 5)
            assert f[f"closure/{name}"].attrs["units"] == unit
    # every grain settled onto the bed: the solids of the propped cells are their w_p A phi_s, exactly
    fields, area = stored["fields"], 0.002 * 0.002
    propped = fields["propped"] > 0
    assert fields["solid_volume"][propped].sum() == pytest.approx((fields["propped_width"] * area * 0.6).sum(),
                                                                  rel=1e-12)
    assert 0.7 * 4e-8 < fields["solid_volume"].sum() < 1.3 * 4e-8   # 10 % of the 1 x 2 cm x 2 mm box
    assert summary["closure_propped_area"] == results.summary["closure_propped_area"] > 0
    assert results.summary["closure_fcd"] == pytest.approx(
        stored["attrs"]["mean_conductivity"] / (0.01 * 9.869232667160130e-16 * stored["attrs"]["propped_half_length"]))
    assert main(["plot", str(out), "--out", str(tmp_path / "plots")]) == 0
    assert (tmp_path / "plots" / "closure_maps.png").is_file()
