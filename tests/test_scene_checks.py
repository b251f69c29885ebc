"""``hfgpu check`` sees what ``hfgpu run`` sees (hfgpu.scene_checks): one warning per rule, every error of a scene
in one report, did-you-mean, the output units chosen by the scene's majority, and the grouped summary and pump
schedule in those units (hfgpu.io.summary)."""

from __future__ import annotations

import math
import tomllib

import pytest

from hfgpu import SceneError, load_scene
from hfgpu.cli import main
from hfgpu.io.summary import schedule_rows, schedule_table, summary_rows, summary_table
from hfgpu.scene_checks import validate
from hfgpu.scene_reader import SceneErrors
from hfgpu.units import count_systems, majority_system

# a layered fracture scene in field units without [output]: 20 ft cells, the pay (9960..10040 ft) is 4 cells tall, its
# boundaries lie half a cell from the rows of cell centres (rows at 10010 ft + k 20 ft)
FIELD = """
[run]
end_time = "20 min"
[rock]
youngs_modulus = "5e6 psi"
poisson_ratio = 0.2
min_stress = "6000 psi"
[[rock.layers]]
top = "9900 ft"
bottom = "9960 ft"
min_stress = "6800 psi"
[[rock.layers]]
top = "9960 ft"
bottom = "10040 ft"
min_stress = "6000 psi"
[[rock.layers]]
top = "10040 ft"
bottom = "10100 ft"
min_stress = "6800 psi"
[fluid]
viscosity = "50 cP"
[injection]
depth = "10010 ft"
schedule = [{ until = "20 min", rate = "20 bbl/min" }]
[mesh]
cell_size = "20 ft"
"""

# a coupled scene in SI: a 100 s pad, then 200 s of sand ramped from 0.1 to 0.2 slurry volume fraction
TWO_STAGE = """
[run]
end_time = "300 s"
physics = ["fracture", "proppant"]
[rock]
youngs_modulus = "45 GPa"
poisson_ratio = 0.2
min_stress = "60 MPa"
[fluid]
viscosity = "2 mPa*s"
[injection]
depth = "3000 m"
schedule = [{ until = "100 s", rate = "0.05 m**3/s" },
            { until = "300 s", rate = "0.05 m**3/s", proppant = "sand", volume_fraction = 0.1, end_volume_fraction = 0.2 }]
[[proppant]]
name = "sand"
size = "40/70"
density = "2650 kg/m**3"
[mesh]
cell_size = "5 m"
[output]
every = "30 s"
"""


def warnings_of(text: str) -> list[str]:
    return list(validate(text).warnings)


def test_the_field_scene_is_clean():
    scene = validate(FIELD)
    assert scene.warnings == ()
    assert scene.output.units == "field" and scene.output.every == 120.0    # [output] left out: end_time / 10


def test_check_reports_in_the_scene_units_with_the_pump_schedule(tmp_path, capsys):
    path = tmp_path / "field.toml"
    path.write_text(FIELD)
    assert main(["check", str(path)]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    lines = out.splitlines()
    assert lines[0] == (f"{path}: ok; physics fracture, end time 1 200 s, cells 20 x 20 ft, output every 120 s, "
                        "units field (the scene's values: 15 in field units, 0 in SI; set [output] units to choose)")
    table = lines.index("pump schedule")
    assert lines[table:table + 4] == [
        "pump schedule",
        "  stage         start [min]  end [min]  rate [bbl/min]  clean [bbl]  slurry [bbl]",
        "  1      fluid            0         20              20          400           400",
        "  total                             20                          400           400"]
    assert lines[table + 4].startswith("expected (a radial fracture at the mean rate 20 bbl/min")
    assert "fracture cells" in lines[-1]


# --- one rule each: a bad scene, the exact message --------------------------------------------------------------

def test_preset_that_coarsens_the_cells_warns_and_shows_the_cells_in_use(tmp_path, capsys):
    text = FIELD.replace("[run]\n", '[run]\npreset = "fast"\n')
    assert warnings_of(text) == [
        'preset "fast" coarsens the cells: [mesh] cell_size 20 ft is run as 40 ft (refinement 0.5); add '
        "'refinement = 1' to [mesh] to keep your cells",
        "rock.layers[1] (80 ft thick) is 2 cells of 40 ft across, fewer than 3: the fracture enters it; use finer "
        "cells"]
    assert warnings_of(text.replace('cell_size = "20 ft"', 'cell_size = "20 ft"\nrefinement = 0.5')) == [
        "rock.layers[1] (80 ft thick) is 2 cells of 40 ft across, fewer than 3: the fracture enters it; use finer "
        "cells"]                                  # the user's own refinement: no preset warning
    path = tmp_path / "fast.toml"
    path.write_text(text)
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "cells 40 x 40 ft" in out and "40 x 40 ft = cell_size 20 x 20 ft / refinement 0.5" in out


def test_coarsening_factor_without_a_cap_warns():
    text = FIELD.replace('cell_size = "20 ft"', 'cell_size = "20 ft"\ncoarsening_factor = 2')
    assert warnings_of(text) == [
        "mesh.coarsening_factor 2 has no effect without mesh.max_cells_across: the grid is never coarsened"]
    assert warnings_of(text.replace("coarsening_factor = 2", "coarsening_factor = 2\nmax_cells_across = 40")) == []


def test_check_refuses_what_the_engine_refuses_after_the_preset(tmp_path, capsys):
    """The issue's case: check said ok, run refused fracture.initial_radius_cells after the preset doubled the cells."""
    path = tmp_path / "short.toml"
    path.write_text(FIELD.replace("[run]\n", '[run]\npreset = "fast"\n').replace('"20 min"', '"60 s"'))
    assert main(["check", str(path)]) == 2
    assert capsys.readouterr().err == (
        "hfgpu check: error: scene key 'fracture.initial_radius_cells': got 2.5; the starting fracture (radius 100 ft: "
        "this many cells of 40 ft x 40 ft in use) would take longer than the schedule to form, past half the "
        "schedule (60 s) or in a stage that does not inject; use finer cells (or a preset that does not coarsen "
        "them)\n")
    assert main(["run", str(path), "--out", str(tmp_path / "r.h5")]) == 2
    assert "scene key 'fracture.initial_radius_cells'" in capsys.readouterr().err
    assert not (tmp_path / "r.h5").exists()


def test_first_stage_at_rate_zero_is_refused_by_check():
    text = FIELD.replace('schedule = [{ until = "20 min", rate = "20 bbl/min" }]',
                         'schedule = [{ until = "1 min", rate = "0 bbl/min" }, { until = "20 min", rate = "20 bbl/min" }]')
    with pytest.raises(SceneError) as info:
        validate(text)
    assert str(info.value) == ("scene key 'injection.schedule[0].rate': got 0.0; the first stage must inject "
                               "(rate > 0) to start a fracture")


@pytest.mark.parametrize("depth, message", [
    ('"10510 ft"', "injection.depth 10 510 ft lies below every layer of [[rock.layers]] (9 900 ft to 10 100 ft): "
                   "the bottom layer's properties are extended to it"),
    ('"9010 ft"', "injection.depth 9 010 ft lies above every layer of [[rock.layers]] (9 900 ft to 10 100 ft): "
                  "the top layer's properties are extended to it"),
])
def test_injection_depth_outside_the_layer_table(depth, message):
    assert warnings_of(FIELD.replace('depth = "10010 ft"', f"depth = {depth}")) == [message]


def test_bare_number_for_a_dimensional_key_is_read_as_si_and_warned_in_an_si_scene():
    si = FIELD.replace('depth = "10010 ft"', "depth = 3051") + '[output]\nunits = "SI"\n'
    assert warnings_of(si) == ["scene key 'injection.depth': bare number 3051 read as 3051 m (SI); write the unit, "
                               'e.g. "3051 m"']
    assert load_scene(si).injection.depth == 3051.0
    # a bare 0 is the same in every unit, and a dimensionless key takes a bare number: no warning
    assert warnings_of(FIELD.replace('min_stress = "6000 psi"\n[[', 'min_stress = 0\n[[')) == []


@pytest.mark.parametrize("end, message", [
    ('"10 min"', "run.end_time 600 s ends before the pump schedule (1 200 s): what is scheduled after 600 s is "
                 "never pumped"),
    ('"30 min"', "run.end_time 1 800 s is after the end of the pump schedule (1 200 s): the last 600 s are shut in; "
                 "a last stage with rate 0 until 1 800 s says so"),
])
def test_end_time_shorter_or_longer_than_the_schedule(end, message):
    assert warnings_of(FIELD.replace('end_time = "20 min"', f"end_time = {end}")) == [message]


def test_a_shut_in_stage_that_ends_at_end_time_silences_the_warning():
    text = FIELD.replace('end_time = "20 min"', 'end_time = "30 min"').replace(
        'rate = "20 bbl/min" }]', 'rate = "20 bbl/min" }, { until = "30 min", rate = "0 bbl/min" }]')
    assert warnings_of(text) == []


def test_zero_rate_pad():
    text = TWO_STAGE.replace('schedule = [{ until = "100 s", rate = "0.05 m**3/s" },',
                             'schedule = [{ until = "50 s", rate = "0.05 m**3/s" }, '
                             '{ until = "100 s", rate = "0 m**3/s" },')
    assert warnings_of(text) == ["injection.schedule[1]: a pad stage at rate 0 (nothing pumped from 50 to 100 s) "
                                 "before pumping goes on; give its rate"]


def test_boundaries_a_whole_number_of_cells_apart_lie_on_faces():
    # the perforation on a face (the grid's rows are placed on the boundaries): 9960 and 10040 ft both on faces
    assert warnings_of(FIELD.replace('depth = "10010 ft"', 'depth = "10000 ft"')) == []


def test_a_boundary_off_every_face_is_named_once_with_a_cell_height_that_honours_it():
    # a 70 ft pay (3.5 cells): faces on 10030 ft, the boundary nearest the perforation; 9960 ft cannot be on one
    text = FIELD.replace('bottom = "10040 ft"', 'bottom = "10030 ft"').replace('top = "10040 ft"', 'top = "10030 ft"')
    assert warnings_of(text) == [
        "rock.layers[0].bottom = rock.layers[1].top 9 960 ft is not on a cell face: the grid's faces (cells 20 ft "
        "tall) are placed on the boundary at 10 030 ft, the nearest to injection.depth 10 010 ft, so a row straddles "
        "9 960 ft with the properties at its centre; cells 17.5 ft tall ([mesh] cell_size height 17.5 ft) put every "
        "layer boundary on a face"]


def test_too_few_cells_across_a_layer_the_fracture_enters():
    text = FIELD.replace('cell_size = "20 ft"', 'cell_size = "40 ft"').replace('depth = "10010 ft"',
                                                                               'depth = "10020 ft"')
    assert warnings_of(text) == ["rock.layers[1] (80 ft thick) is 2 cells of 40 ft across, fewer than 3: the "
                                 "fracture enters it; use finer cells"]


def test_check_and_run_print_warnings_the_same_way(tmp_path, capsys, monkeypatch):
    import hfgpu.runner

    path = tmp_path / "late.toml"
    path.write_text(FIELD.replace('end_time = "20 min"', 'end_time = "10 min"'))
    line = ("hfgpu: warning: run.end_time 600 s ends before the pump schedule (1 200 s): what is scheduled after "
            "600 s is never pumped\n")
    assert main(["check", str(path)]) == 0
    assert capsys.readouterr().err == line

    def stop(*args, **kwargs):
        raise SceneError("(test)", None, "stopped before the run")
    monkeypatch.setattr(hfgpu.runner, "simulator_for", stop)
    assert main(["run", str(path), "--out", str(tmp_path / "r.h5"), "--no-progress"]) == 2
    assert capsys.readouterr().err.startswith(line)


# --- errors -------------------------------------------------------------------------------------------------------

def test_all_errors_of_a_scene_in_one_report(tmp_path, capsys):
    text = (FIELD.replace("poisson_ratio = 0.2", "poisson_ratio = 0.7")
            .replace('viscosity = "50 cP"', 'viscosity = "-1 cP"')
            .replace('cell_size = "20 ft"', 'cell_size = "20 ft"\ncells = 3')
            .replace('bottom = "10100 ft"', 'bottom = "10000 ft"'))
    with pytest.raises(SceneErrors) as info:
        load_scene(text)
    assert [e.path for e in info.value.errors] == ["fluid.viscosity", "mesh.cells", "rock.poisson_ratio",
                                                   "rock.layers[2].bottom"]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert main(["check", str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.splitlines() == [
        "hfgpu check: error: scene key 'fluid.viscosity': got '-1 cP'; allowed: > 0 Pa*s",
        "hfgpu check: error: scene key 'mesh.cells': got 3; unknown key; did you mean 'cell_size'? keys allowed "
        "here: cell_size, coarsening_factor, max_cells_across, refinement",
        "hfgpu check: error: scene key 'rock.poisson_ratio': got 0.7; allowed: >= 0 and < 0.5",
        "hfgpu check: error: scene key 'rock.layers[2].bottom': got '10000 ft'; a layer's bottom must lie below its "
        "top ('10040 ft'); depth is positive downward"]


def test_overlapping_layers_are_named_in_the_scene_units():
    with pytest.raises(SceneError) as info:
        load_scene(FIELD.replace('top = "10040 ft"', 'top = "10030 ft"'))
    assert str(info.value) == ("scene key 'rock.layers[2].top': got '10030 ft'; layers must not overlap: "
                               "rock.layers[1] spans 9 960 ft to 10 040 ft, rock.layers[2] spans 10 030 ft to "
                               "10 100 ft")


def test_a_dependent_section_is_not_reported_twice():
    """A bad [fluid] stops [[proppant]] (which needs it); the injection's proppant name is then not judged."""
    with pytest.raises(SceneError) as info:
        load_scene(TWO_STAGE.replace('viscosity = "2 mPa*s"', 'viscosity = "2 m"'))
    assert not isinstance(info.value, SceneErrors) and info.value.path == "fluid.viscosity"


def test_did_you_mean_for_an_unknown_key_and_a_misspelt_required_one():
    with pytest.raises(SceneError) as info:
        load_scene(FIELD.replace("[fluid]\n", "[fluid]\ndensty = \"8.4 lb/gal\"\n"))
    assert str(info.value).startswith("scene key 'fluid.densty': got '8.4 lb/gal'; unknown key; did you mean "
                                      "'density'? keys allowed here: density, viscosity")
    with pytest.raises(SceneError) as info:
        load_scene(FIELD.replace("youngs_modulus =", "youngs_modulous ="))
    assert str(info.value) == ("scene key 'rock.youngs_modulus': got (missing); this key is required; found "
                               "'youngs_modulous': did you mean 'youngs_modulus'?")


# --- units --------------------------------------------------------------------------------------------------------

def test_output_units_default_to_the_scene_majority():
    assert load_scene(FIELD).output.units == "field"                       # 15 field values, 0 SI
    assert load_scene(TWO_STAGE).output.units == "SI"
    assert load_scene(FIELD + '[output]\nunits = "SI"\n').output.units == "SI"          # said: it wins
    few = TWO_STAGE.replace('depth = "3000 m"', 'depth = "9843 ft"').replace('"0.05 m**3/s"', '"18.9 bbl/min"')
    assert count_systems(tomllib.loads(few)) == {"SI": 5, "field": 3} and load_scene(few).output.units == "SI"
    # time units, names, sieve labels and bare numbers are not counted; a tie gives SI
    tie = {"a": "1 ft", "b": "1 m", "c": "1 min", "d": "40/70", "e": 3, "f": [{"g": "sand"}]}
    assert count_systems(tie) == {"SI": 1, "field": 1} and majority_system(tie) == "SI"
    assert majority_system({"a": ["2 ppa", "1 cP"], "b": "1 MPa"}) == "field"


SUMMARY = {  # a coupled run's summary as the runner makes it (fracture_* from the engine, the rest from the bar)
    "fracture_area": 2000.0, "fracture_length": 80.0, "fracture_height": 30.0, "fracture_w_inlet": 0.004,
    "net_pressure_end": 1.5e6, "injection_pressure_end": 61.5e6, "injected_volume": 15.0, "stored_volume": 9.0,
    "leaked_volume": 6.0, "efficiency": 0.6, "balance_error": 1e-7, "proppant_injected": 1.5,
    "proppant_in_domain": 1.2, "proppant_screened_out": 0.3, "proppant_screen_out_time": math.nan,
    "proppant_outflow": 0.0, "proppant_parcels": 12000, "closure_propped_area": 500.0, "closure_fcd": math.nan,
    "closure_propped_half_length": 20.0, "closure_propped_height": 12.5, "closure_mean_conductivity": 1e-12,
    "closure_time": 300.0, "closure_settling": "bed", "closure_permeability_model": "kozeny-carman",
    "status": "complete", "sim_time": 300.0, "wall_time": 12.3456, "fracture_steps": 250, "proppant_steps": 900,
    "proppant_backend": "taichi", "proppant_arch": "x64", "resumed_from": math.nan, "out": "r.h5", "steps": 250,
    "fracture_time": 300.0, "time": 300.0, "checkpoints": 2}


@pytest.mark.parametrize("system, expect", [
    ("SI", {"created area (one face)": "2 000 m^2", "width at the perforation": "4 mm", "net pressure at the end": "1.5 MPa",
            "pumped": "15 m^3", "fluid efficiency": "60 %", "held back at the inlet": "795 kg (20 % of pumped)",
            "screen-out began": "never", "propped area (after closure)": "500 m^2 (25 % of created)"}),
    ("field", {"created area (one face)": "21 530 ft^2", "width at the perforation": "0.1575 in",
               "net pressure at the end": "217.6 psi", "pumped": "94.35 bbl", "fluid efficiency": "60 %",
               "held back at the inlet": "1 753 lb (20 % of pumped)", "screen-out began": "never",
               "propped area (after closure)": "5 382 ft^2 (25 % of created)"}),
])
def test_grouped_summary_in_si_and_field(system, expect):
    expect = dict(expect)
    scene = load_scene(TWO_STAGE)
    rows = summary_rows(SUMMARY, system, 2650.0)
    assert [g for g, _, _ in rows] == sorted((g for g, _, _ in rows), key=["fracture", "fluid", "proppant",
                                                                             "run"].index)
    labels = [(g, label) for g, label, _ in rows]
    assert len(labels) == len(set(labels))                                   # no duplicates
    assert not any("nan" in text.lower() for _, _, text in rows)             # no nan: "never" or left out
    assert "F_CD" not in [label for _, label, _ in rows] and "resumed from" not in [label for _, label, _ in rows]
    found = {label: text for _, label, text in rows}
    pumped_fluid = [text for g, label, text in rows if label == "pumped" and g == "fluid"][0]
    assert pumped_fluid == expect.pop("pumped")
    for label, text in expect.items():
        assert found[label] == text, label
    table = summary_table(SUMMARY, system, scene)
    assert table.splitlines()[0] == "fracture" and "\nrun\n" in table and "nan" not in table
    assert len(table.splitlines()) < 40


def test_pump_schedule_against_a_hand_computation():
    scene = load_scene(TWO_STAGE)
    pad, sand = schedule_rows(scene)
    assert (pad["kind"], pad["start"], pad["end"], pad["rate"]) == ("pad", 0.0, 100.0, 0.05)
    assert pad["slurry_volume"] == pytest.approx(5.0) and pad["clean_volume"] == pytest.approx(5.0)
    # 200 s at 0.05 m^3/s = 10 m^3 of slurry; mean fraction 0.15: 1.5 m^3 of sand = 3975 kg, 8.5 m^3 clean;
    # concentration rho phi / (1 - phi): 2650 x 0.1 / 0.9 = 294.4 and 2650 x 0.2 / 0.8 = 662.5 kg/m^3
    assert sand["kind"] == "slurry" and (sand["start"], sand["end"]) == (100.0, 300.0)
    assert sand["slurry_volume"] == pytest.approx(10.0, rel=1e-12)
    assert sand["solid_volume"] == pytest.approx(1.5, rel=1e-12)
    assert sand["clean_volume"] == pytest.approx(8.5, rel=1e-12)
    assert sand["mass"] == pytest.approx(3975.0, rel=1e-12)
    assert sand["concentration_start"] == pytest.approx(2650 * 0.1 / 0.9, rel=1e-12)
    assert sand["concentration_end"] == pytest.approx(662.5, rel=1e-12)
    assert schedule_table(scene, "SI").splitlines() == [
        "pump schedule",
        "  stage               start [s]  end [s]  rate [m^3/min]  clean [m^3]  slurry [m^3]  proppant [kg]  "
        "conc. [kg/m^3]",
        "  1      pad                  0      100               3            5             5              -"
        "               -",
        "  2      slurry sand        100      300               3          8.5            10          3 975"
        "     294.4-662.5",
        "  total                              300                         13.5            15          3 975"]
    field = schedule_table(scene, "field").splitlines()
    # 3 m^3/min = 18.87 bbl/min; 13.5 m^3 = 84.91 bbl; 3975 kg = 8763 lb; 294.4 kg/m^3 = 2.457 ppa, 662.5 = 5.529
    assert "rate [bbl/min]" in field[1] and "proppant [lb]" in field[1] and "conc. [ppa]" in field[1]
    assert "8 763" in field[3] and "2.457-5.529" in field[3] and "18.87" in field[2] and "84.91" in field[4]


def test_an_unknown_key_in_a_long_table_lists_the_keys_in_one_short_line():
    """[fracture] has 16 keys: the list is cut at KEY_LIST_CHARS characters and says how many there are."""
    from hfgpu.scene_reader import KEY_LIST_CHARS, key_list

    names = [f"key_{i:02d}_of_a_long_table" for i in range(16)]
    text = key_list(names)
    assert text.startswith("key_00_of_a_long_table, key_01") and text.endswith(", ... (16 keys; docs/scene.md)")
    assert len(text) <= KEY_LIST_CHARS + len(", ... (16 keys; docs/scene.md)")
    assert key_list(["a", "b"]) == "a, b" and key_list([]) == "(none)"
