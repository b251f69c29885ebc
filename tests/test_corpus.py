"""Four treatments of the benchmark corpus (bench/scenes/corpus_*.toml, bench/bench_corpus.py), as an engineer
wrote them, run end to end with the ``fast`` preset and their numerical knobs at the defaults: three shortened to
fit CI with ``hfgpu.edit_scene`` (a one-minute pad, three for the 200 cP gel, and a minute of sand, the issue-30
stage's two sands 30 s each), the two-sand linear gel whole (45 min with a 15 min shut-in over a settled bed).
Each run must complete, keep its proppant (solid balance |injected - in_domain - outflow - screened_out| /
injected below 1e-6) and prop some area. ~15 s on one core with a warm kernel cache."""

from __future__ import annotations

from pathlib import Path

import pytest

from hfgpu import edit_scene, load_scene, open_results, run

SCENES = Path(__file__).resolve().parents[1] / "bench" / "scenes"
#: Relative solid-volume balance error allowed at the end of a run (round-off is ~1e-15).
SOLID_BALANCE = 1e-6
#: scene -> the keys that shorten it (the rest of the scene as written).
SHORT = {
    "corpus_permian_slickwater_stage": {  # issue 30's stage: 100 mesh, then 40/70
        "injection.schedule[0].duration": "1 min", "injection.schedule[1].duration": "30 s",
        "injection.schedule[2].duration": "30 s", "run.end_time": "2 min", "output.every": "30 s"},
    "corpus_gulf_coast_crosslinked_2040": {  # issue 30's viscous one: 200 cP, 20/40 at 2 -> 6 ppa
        # a 3 min pad: at 40 ft cells (fast) the 200 cP fracture fills its first cells at 120 s
        "injection.schedule[0].duration": "3 min", "injection.schedule[1].duration": "1 min",
        "run.end_time": "4 min", "output.every": "30 s"},
    "corpus_shallow_test_linear_gel_10bpm": {  # 30 cP, 40/70, 5 ft cells
        "injection.schedule[0].duration": "1 min", "injection.schedule[1].duration": "1 min",
        "run.end_time": "2 min", "output.every": "30 s"},
    # whole, with its 15 min shut-in: the settled bed whose pressure loop stopped it (docs/stability.md)
    "corpus_gulf_coast_linear_gel_two_sand": {},
}


@pytest.mark.parametrize("name", list(SHORT))
def test_a_corpus_scene_completes_and_props(name, tmp_path):
    path = SCENES / f"{name}.toml"
    scene = edit_scene(load_scene(path.read_text()), {"run.preset": "fast", **SHORT[name]})
    out = tmp_path / f"{name}.h5"
    try:
        run(scene, out, progress=False)
    except Exception as error:  # the file's status says the same; the message is the useful part
        pytest.fail(f"{name} (fast, shortened) failed: {type(error).__name__}: {error}")
    r = open_results(out)
    assert r.status == "complete"
    b = {k: float(v[-1]) for k, v in r.proppant_balance.items()}
    assert b["injected"] > 0.0
    lost = b["injected"] - b["in_domain"] - b["outflow"] - b.get("screened_out", 0.0)
    assert abs(lost) < SOLID_BALANCE * b["injected"], b
    assert r.summary["closure_propped_area"] > 0.0
