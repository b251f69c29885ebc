"""A clean terminal (issue 15 item 7): one labelled bar per phase with the simulated time and the time left;
warnings raised during a run are held and printed after the bars as one ``hfgpu: warning:`` line each."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from hfgpu.io.progress import Progress

HERE = Path(__file__).resolve().parent
SCRIPT = Path(sys.executable).with_name("hfgpu")
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "hfgpu.cli"]


def _lines(text: str) -> list[str]:
    """The terminal's lines: tqdm redraws with carriage returns."""
    return [line.strip() for line in re.split(r"[\r\n]+", text) if line.strip()]


def test_one_bar_per_phase_then_the_held_warnings():
    out = io.StringIO()
    bar = Progress(40.0, file=out, phase="fracture")
    with bar.holding_warnings():
        for t in (10.0, 40.0):
            bar(t)
        warnings.warn("the fracture width history\non the proppant grid is not mass-consistent", RuntimeWarning)
        bar.phase("proppant", 20.0)
        bar(30.0)
        bar(25.0)  # earlier: ignored
        warnings.warn("the fracture width history\non the proppant grid is not mass-consistent", RuntimeWarning)
        bar(40.0)
    bar.close()
    lines = _lines(out.getvalue())
    assert bar.phases == ["fracture", "proppant"] and bar.time == 40.0
    assert lines[-1] == "hfgpu: warning: the fracture width history on the proppant grid is not mass-consistent"
    assert sum(line.startswith("hfgpu: warning:") for line in lines) == 1  # once, after both bars
    assert lines[-2].startswith("proppant: 100%") and "40/40 s simulated" in lines[-2] and " left]" in lines[-2]
    assert any(line.startswith("fracture: 100%") for line in lines)
    assert any(line.startswith("proppant:  50%") and "20/40 s simulated" in line for line in lines)  # its start
    assert ".py:" not in out.getvalue()


def test_hidden_bar_lets_warnings_through():
    out = io.StringIO()
    bar = Progress(1.0, file=out, enabled=False)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with bar.holding_warnings():
            warnings.warn("seen by the caller", RuntimeWarning)
    bar.close()
    assert [str(w.message) for w in caught] == ["seen by the caller"] and out.getvalue() == ""


@pytest.fixture(scope="module")
def screened(tmp_path_factory):
    """A real coupled run through the CLI: the tiny layered scene with large grains that screen out (seconds)."""
    folder = tmp_path_factory.mktemp("screened")
    scene = (HERE / "scenes" / "tiny_coupled.toml").read_text()
    path = folder / "screened.toml"
    path.write_text(scene.replace("volume_fraction = 0.1", "volume_fraction = 0.3").replace('"300 um"', '"500 um"'))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    done = subprocess.run([*COMMAND, "run", str(path), "--out", str(folder / "r.h5")], capture_output=True,
                          text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    return done, folder / "r.h5"


def test_coupled_run_terminal(screened):
    """A "fracture" bar, then a "proppant" bar, then the screen-out warning as one line without source paths."""
    done, _ = screened
    lines = _lines(done.stderr)
    phases = [line.split(":")[0] for line in lines if "s simulated" in line]
    assert phases and set(phases) == {"fracture", "proppant"}
    assert phases.index("proppant") > max(i for i, p in enumerate(phases) if p == "fracture")  # one after the other
    last_bar = max(i for i, line in enumerate(lines) if "s simulated" in line)
    tail = lines[last_bar + 1:]
    assert tail and all(line.startswith("hfgpu: warning: ") for line in tail), lines
    assert any("screen-out: the inlets held back" in line for line in tail)
    assert "Warning:" not in done.stderr and ".py:" not in done.stderr
    assert "status" in done.stdout


def test_coupled_run_maps_show_layers_and_bridging(screened):
    """The same run's maps: the layer boundaries at 494 and 506 m on every map that spans them, the red bridging
    outlines in the legend of the proppant maps, no 'nan' in a title."""
    from hfgpu.io.plots import LAYER_STYLE, figures
    from hfgpu.io.results import open_results

    out = figures(open_results(screened[1]))
    legend = out["proppant_maps"].axes[0].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == [
        "layer boundary", "bridging risk (width < bridging_factor x grain diameter)"]
    for name in ("proppant_maps", "proppant_volume_fraction", "proppant_streamlines", "closure_maps"):
        maps = [ax for ax in out[name].axes if ax.get_ylabel() == "depth z [m]"]
        assert maps, name
        for ax in maps:
            depths = sorted(float(line.get_ydata()[0]) for line in ax.get_lines()
                            if line.get_color() == LAYER_STYLE["color"])
            assert depths == [494.0, 506.0], (name, ax.get_title())
    titles = [ax.get_title() for figure in out.values() for ax in figure.axes]
    assert not any("nan" in title.lower() for title in titles)
