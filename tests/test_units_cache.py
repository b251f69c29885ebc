"""The unit registry survives a corrupt pint disk cache (parallel processes on a fresh machine read each other's
half-written cache files): it is built without the cache instead of failing."""

import pint
import pytest

from hfgpu import units


def test_registry_is_built_without_a_cache_it_cannot_read(monkeypatch):
    real = pint.UnitRegistry
    calls = []

    def registry(*args, **kwargs):
        calls.append(kwargs.get("cache_folder"))
        if kwargs.get("cache_folder") is not None:
            raise UnicodeDecodeError("utf-8", b"\x95", 0, 1, "invalid start byte")  # what flexcache raised
        return real(*args, **kwargs)

    monkeypatch.setattr(units.pint, "UnitRegistry", registry)
    units.registry.cache_clear()
    try:
        ureg = units.registry()
        assert calls == [":auto:", None]
        assert ureg.Quantity(5, "bpm").to("m**3/s").magnitude == pytest.approx(0.013249, rel=1e-4)
    finally:
        units.registry.cache_clear()
