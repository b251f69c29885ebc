"""The docs name only what exists: every figure file a doc lists is one that ``hfgpu plot`` (or a sweep, a demo,
a bench script, docs/figures/) writes, and every flag of an ``hfgpu`` command in a doc is one its parser has."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from hfgpu.cli import _parser
from hfgpu.io.plots import FIGURE_NAMES

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
CODE = re.compile(r"```\w*\n(.*?)```|`([^`\n]+)`", re.S)
COMMAND = re.compile(r"\bhfgpu\s+(\w+)((?:\s+[^\s|;&#]+)*)")


def _code(path: Path) -> list[str]:
    """The code of a doc: each line of its fenced blocks and each inline code span."""
    out = []
    for block, span in CODE.findall(path.read_text()):
        out.extend(block.splitlines() if block else [span])
    return out


def _subcommands() -> dict[str, set[str]]:
    """Each ``hfgpu`` command's option strings (argparse)."""
    parser = _parser()
    action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return {name: {s for a in sub._actions for s in a.option_strings} for name, sub in action.choices.items()}


def _figure_stems() -> set[str]:
    """Every figure name the code writes: hfgpu.io.plots (FIGURE_NAMES), the sweep figures of
    hfgpu/ensemble/plots.py, the PNG names in demos/ and bench/, and docs/figures/."""
    stems = {name for names in FIGURE_NAMES.values() for name in names}
    ensemble = (ROOT / "hfgpu" / "ensemble" / "plots.py").read_text()
    stems |= set(re.findall(r'figures\["(\w+)"\]', ensemble))
    if "distribution_" in ensemble:
        stems.add("distribution_<metric>")
    for script in [*(ROOT / "demos").glob("*.py"), *(ROOT / "bench").glob("*.py")]:
        stems |= set(re.findall(r"""["'/](\w+)\.png""", script.read_text()))
    stems |= {p.stem for p in (ROOT / "docs" / "figures").glob("*.png")}
    return stems


def test_plots_figure_names_are_what_figures_returns():
    """FIGURE_NAMES is the full list: the fakes' figure names fall in it (see tests/io/test_figures_trust.py for
    the kinds of results)."""
    stems = [name for names in FIGURE_NAMES.values() for name in names]
    assert len(stems) == len(set(stems)) and "proppant_interfaces" in stems and "pressure_history" in stems


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_listed_figures_exist(doc):
    known = _figure_stems()
    listed = set(re.findall(r"([\w<>]+)\.png", " ".join(_code(doc))))
    listed -= {"OUT", "wu", "radial"}  # a user's own output names in example commands
    unknown = {name for name in listed if name not in known and not name.isupper()}
    assert not unknown, f"{doc.name} lists figures no code writes: {sorted(unknown)}"


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_hfgpu_flags_exist(doc):
    commands = _subcommands()
    wrong = []
    for line in _code(doc):
        for name, rest in COMMAND.findall(line):
            if name not in commands:
                if not line.lstrip().startswith(("import", "from")) and name not in ("io", "scenes"):
                    wrong.append(f"hfgpu {name}")
                continue
            for flag in re.findall(r"(?<![\w-])(--?[a-z][\w-]*)", rest):
                if flag not in commands[name]:
                    wrong.append(f"hfgpu {name} {flag}")
    assert not wrong, f"{doc.name} names what the hfgpu parser does not have: {wrong}"


def test_every_doc_flag_of_the_cli_exists():
    """A flag written alone in a doc's code (e.g. `--resume`) is a flag of some hfgpu command, of a demo or bench
    script, or of pytest (lines of pip, rerun and dask commands are theirs)."""
    flags = set().union(*_subcommands().values())
    for script in [*(ROOT / "demos").glob("*.py"), *(ROOT / "bench").glob("*.py")]:
        flags |= set(re.findall(r"""add_argument\(\s*["'](--[\w-]+)""", script.read_text()))
    flags |= {"-m", "-q", "-x", "-k", "--help"}
    wrong = {}
    for doc in DOCS:
        for line in _code(doc):
            if re.search(r"\bpip\b|\bpython3? -m venv\b|\brerun\s+-|\bdask\b|dask-", line):
                continue  # other tools' flags
            unknown = {f for f in re.findall(r"(?<![\w\-./=])(--[a-z][\w-]*)", line) if f not in flags}
            if unknown:
                wrong.setdefault(doc.name, set()).update(unknown)
    assert not wrong, wrong
