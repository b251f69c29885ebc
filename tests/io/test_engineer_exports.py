"""What an engineer reads and exports (issue 31, findings 3, 6 and 8), run as a user runs it (the ``hfgpu``
command in a subprocess): the export of a fracture-only run in every format, the StimPlan grid of a coupled run
covering the whole fracture, the surface treating pressure stored in the results file and read back from there,
a ``[wellbore]`` error in the scene's units, and the summary's height."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import numpy as np
import pytest

from hfgpu import load_scene, open_results
from hfgpu.fracture.geometry import footprint
from hfgpu.io.summary import summary_rows
from hfgpu.units import convert, format_number
from hfgpu.wellbore import surface_pressure

HFGPU = [sys.executable, "-c", "import sys; from hfgpu.cli import main; sys.exit(main())"]
TINY = (Path(__file__).parent.parent / "scenes" / "tiny_coupled.toml").read_text()
#: The tiny coupled scene on proppant cells a third of the fracture's cells' height: its proppant grid does not
#: reach the fracture box's margin rows.
FINE = TINY.replace('fracture_every = "5 s"', 'fracture_every = "5 s"\ncell_size = ["1.5 m", "0.5 m"]')
#: The tutorial's first scene (docs/tutorial.md): 10 ft cells, a 50 ft pay between 7000 psi barriers, with a
#: wellbore, so that its history has a surface treating pressure.
FRACTURE = """
[run]
end_time = "4 min"

[rock]
youngs_modulus = "4e6 psi"
poisson_ratio = 0.25
toughness = "1000 psi*in**0.5"
leakoff_coefficient = "0.0005 ft/min**0.5"

[[rock.layers]]
top = "7900 ft"
bottom = "8000 ft"
min_stress = "7000 psi"

[[rock.layers]]
top = "8000 ft"
bottom = "8050 ft"
min_stress = "6000 psi"

[[rock.layers]]
top = "8050 ft"
bottom = "8150 ft"
min_stress = "7000 psi"

[fluid]
viscosity = "20 cP"

[injection]
depth = "8025 ft"
schedule = [{ until = "4 min", rate = "5 bbl/min" }]

[wellbore]
measured_depth = "8600 ft"
inner_diameter = "4 in"

[mesh]
cell_size = "10 ft"

[output]
every = "1 min"
units = "field"
"""
PSI = convert(1.0, "Pa", "psi")
INCH = convert(1.0, "m", "in")


def hfgpu(*args, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*HFGPU, *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def fracture_run(tmp_path_factory) -> tuple[Path, str, str]:
    """(results file, stdout, stderr) of the fracture-only field scene (about 2 s)."""
    folder = tmp_path_factory.mktemp("fracture")
    (folder / "frac.toml").write_text(FRACTURE)
    done = hfgpu("run", "frac.toml", "--out", "frac.h5", cwd=folder)
    assert done.returncode == 0, done.stderr
    return folder / "frac.h5", done.stdout, done.stderr


@pytest.fixture(scope="module")
def coupled_run(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("coupled")
    (folder / "fine.toml").write_text(FINE)
    done = hfgpu("run", "fine.toml", "--out", "fine.h5", "--no-progress", cwd=folder)
    assert done.returncode == 0, done.stderr
    return folder / "fine.h5"


def _numbers(text: str) -> np.ndarray:
    return np.array(text.replace("[", " ").replace("]", " ").split(), dtype=float)


def read_stimplan(path: Path) -> dict:
    """xs, ys (as written) and {property name: (uom, rows)} of a StimPlan XML file."""
    root = ET.parse(path).getroot()
    grid = root.find("grid")
    properties = {p.get("name"): (p.get("uom"), np.array([_numbers(d.text) for d in p.iter("data")]))
                  for p in root.find("properties")}
    return dict(xs=_numbers(grid.find("xs").text), ys=_numbers(grid.find("ys").text), uom=grid.get("uom"),
                properties=properties)


def test_a_fracture_only_run_exports_its_created_geometry_in_every_format(fracture_run, tmp_path):
    path, _, _ = fracture_run
    snap = open_results(path).fracture_snapshots[-1]
    for fmt, out in (("stimplan-xml", "frac.xml"), ("csv", "frac.csv"), ("vtk", "frac")):
        done = hfgpu("export", path, "--format", fmt, "--out", tmp_path / out, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        assert done.stderr == "" and done.stdout.strip()
    data = read_stimplan(tmp_path / "frac.xml")
    assert data["uom"] == "ft" and set(data["properties"]) == {"HYDRAULIC_WIDTH", "PRESSURE"}
    assert data["xs"].size == snap.width.shape[1] and data["ys"].size == snap.width.shape[0]
    assert 0.0 in data["xs"]   # the well's column at x = 0 exactly, no 9.3e-13
    uom, rows = data["properties"]["HYDRAULIC_WIDTH"]
    np.testing.assert_allclose(rows, snap.width * INCH, rtol=1e-7, atol=1e-12)
    assert uom == "in" and np.count_nonzero(rows) == np.count_nonzero(snap.width) > 0
    uom, rows = data["properties"]["PRESSURE"]
    np.testing.assert_allclose(rows, snap.pressure * PSI, rtol=1e-7)
    assert uom == "psi"
    lines = (tmp_path / "frac.csv").read_text().splitlines()
    assert lines[0] == "x [ft],depth [ft],width [in],pressure [psi]"
    table = np.loadtxt(tmp_path / "frac.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(table[:, 2], snap.width.ravel() * INCH, rtol=1e-9)
    assert (tmp_path / "frac_fracture.pvd").is_file() and (tmp_path / "frac_pressure.csv").is_file()


def test_the_stimplan_grid_of_a_coupled_run_covers_the_whole_fracture(coupled_run, tmp_path):
    done = hfgpu("export", coupled_run, "--format", "stimplan-xml", "--units", "SI", "--out", "c.xml",
                 cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    results = open_results(coupled_run)
    snap = results.fracture_snapshots[-1]
    closure = results.closure
    data = read_stimplan(tmp_path / "c.xml")
    depths = data["ys"][::-1]   # ys run from the deepest up
    f, p = snap.frame, closure["frame"]
    assert depths[0] - p.dz / 2 <= f.z0 - f.dz / 2 + 1e-9      # the fracture box's top row is inside
    assert depths[-1] + p.dz / 2 >= f.z0 + (snap.width.shape[0] - 0.5) * f.dz - 1e-9
    assert depths.size > closure["fields"]["propped_width"].shape[0]   # more rows than the proppant grid
    assert {"WIDTH", "CONDUCTIVITY", "PERMEABILITY", "HYDRAULIC_WIDTH", "PRESSURE"} <= set(data["properties"])
    _, hydraulic = data["properties"]["HYDRAULIC_WIDTH"]
    cell_area = p.dx * p.dz
    # every open fracture cell is on the map: the created volume on the map is the snapshot's
    assert (hydraulic / 100.0).sum() * cell_area == pytest.approx(snap.width.sum() * f.dx * f.dz, rel=1e-7)
    _, propped = data["properties"]["WIDTH"]
    outside = (depths < p.z0 - p.dz / 2) | (depths > p.z0 + (closure["fields"]["propped_width"].shape[0] - 0.5) * p.dz)
    assert outside.any() and not propped[outside].any()   # no proppant grid there: 0
    np.testing.assert_allclose(propped[~outside] / 100.0, closure["fields"]["propped_width"], rtol=1e-7, atol=1e-15)


def test_surface_treating_pressure_is_stored_and_read_back_from_the_file(fracture_run, tmp_path):
    path, stdout, _ = fracture_run
    with h5py.File(path, "r") as f:
        column = f["fracture/balance/surface_pressure"]
        assert column.attrs["units"] == "Pa"
        stored, time, bhtp = column[()], f["fracture/balance/time"][()], f["fracture/balance/injection_pressure"][()]
    scene = load_scene(FRACTURE)
    np.testing.assert_allclose(stored, surface_pressure(scene, time, bhtp), rtol=1e-12)
    line = next(x for x in stdout.splitlines() if "STP (surface treating pressure), end" in x)
    assert line.endswith(f" {format_number(stored[-1] * PSI)} psi")
    copy = tmp_path / "copy.h5"   # a stored history the scene would not give: the summary reads the file's
    shutil.copy(path, copy)
    with h5py.File(copy, "r+") as f:
        f["fracture/balance/surface_pressure"][...] = 1234.0 / PSI
    done = hfgpu("summary", copy, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert re.search(r"STP \(surface treating pressure\), end\s+1 234 psi$", done.stdout, re.M)


def test_a_wellbore_depth_error_speaks_the_scenes_units(tmp_path):
    (tmp_path / "bad.toml").write_text(FRACTURE.replace('measured_depth = "8600 ft"', 'measured_depth = "8000 ft"'))
    done = hfgpu("check", "bad.toml", cwd=tmp_path)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert "'wellbore.measured_depth'" in done.stderr and "depth = 8 025 ft)" in done.stderr
    assert not re.search(r"\d m\b", done.stderr)


def test_the_summary_height_of_a_known_footprint_is_its_open_rows():
    """5 wholly open rows of 10 ft cells are 50 ft high, as the summary prints it."""
    cell = convert(10.0, "ft", "m")
    size = footprint(np.ones((5, 12)), cell, cell)
    rows = dict((label, text) for group, label, text in summary_rows(size, "field") if group == "fracture")
    assert rows["height"] == "50 ft" and rows["length (tip to tip)"] == "120 ft"
    assert rows["created area (one face)"] == "6 000 ft^2"


def test_the_summary_height_is_the_extent_of_the_open_rows(fracture_run):
    """5 open rows of 10 ft between 1000 psi barriers: 50 ft. The barrier cells the front criterion opened at
    the last step, which the next solve would hold shut, are no fracture height (front_cells.CellFront.held)."""
    path, stdout, _ = fracture_run
    snap = open_results(path).fracture_snapshots[-1]
    open_rows = int((snap.width > 0).sum(axis=0).max())
    line = next(x for x in stdout.splitlines() if x.strip().startswith("height"))
    assert open_rows == 5 and line.split()[-2:] == [format_number(open_rows * 10.0), "ft"]
    assert all(abs(float(s.extras["height"]) - 5 * convert(10.0, "ft", "m")) < 1e-9
               for s in open_results(path).fracture_snapshots)


def test_the_summary_speaks_one_style_in_field_units(fracture_run):
    """Numbers grouped by a space ("13 020"), never "13,020" or an ungrouped "13020"; the area says it is one
    face; the schedule in minutes; a log redirected to a file holds a few plain lines per phase, no bar frames."""
    _, stdout, stderr = fracture_run
    table = stdout[stdout.index("pump schedule"):]
    assert not re.search(r"\d,\d{3}", table) and not re.search(r"(?<![\d.])\d{5,}", table)
    assert re.search(r"created area \(one face\)\s+\d{1,3}( \d{3})* ft\^2$", table, re.M)
    assert "start [min]" in table and "end [min]" in table
    progress = [line for line in stderr.splitlines() if line.startswith("fracture:")]
    assert 1 <= len(progress) <= 12 and "\r" not in stderr
