"""The sweep's P10/P50/P90 printed at the end are in the base scene's units (issue 31)."""

import math

import pytest

from hfgpu.ensemble.execute import percentile_lines


def _rows():
    # 6500 psi = 44815922.4 Pa; 1000 ft^2 = 92.90304 m^2; a failed member is left out
    pressures = [44815922.405594364, 2 * 44815922.405594364, 3 * 44815922.405594364]
    rows = [{"id": f"m{i}", "status": "complete", "net_pressure_end": p, "created_area": 92.90304 * (i + 1),
             "efficiency": 0.5} for i, p in enumerate(pressures)]
    return rows + [{"id": "bad", "status": "failed: x", "net_pressure_end": 1e12, "created_area": 1e9,
                    "efficiency": math.nan}]


def _values(line):
    return [float(word) for word in line.split() if word.replace(".", "", 1).replace("e+", "", 1).isdigit()]


def test_percentiles_in_field_units():
    lines = percentile_lines(_rows(), ["net_pressure_end", "created_area", "efficiency"], "field")
    pressure, area, efficiency = lines
    assert "net_pressure_end [psi]" in pressure and "created_area [ft^2]" in area and "efficiency [-]" in efficiency
    p10, p50, p90 = _values(pressure)
    assert p50 == pytest.approx(13000, rel=1e-3) and p10 == pytest.approx(7800, rel=1e-3)
    assert p90 == pytest.approx(18200, rel=1e-3)
    assert _values(area)[1] == pytest.approx(2000, rel=1e-3)
    assert _values(efficiency) == pytest.approx([0.5, 0.5, 0.5])


def test_percentiles_in_si_units():
    (pressure,) = percentile_lines(_rows(), ["net_pressure_end"], "SI")
    assert "[MPa]" in pressure and _values(pressure)[1] == pytest.approx(89.63, rel=1e-3)
