"""What a closure family needs to define its Taichi twins without importing Taichi: importing a family for its
NumPy reference must not start Taichi (a NumPy run never loads it, tests/proppant/test_conservation.py), and
``import taichi`` lives in hfgpu.kernels.runtime alone.

``ti`` stands for hfgpu.kernels.runtime's ``ti``: ``ti.func`` marks a Taichi function that ``ti.func`` builds on
the first call from a kernel being compiled (Taichi inlines it as any ``@ti.func``: the object carries
``_is_taichi_function``); any other attribute (``ti.min``, ``ti.select``, ...) is Taichi's, looked up when a
kernel is compiled. ``Deferred(module)`` is a module imported on first attribute access (e.g. the inline exp and
log of hfgpu.kernels.elementary, which import Taichi). A twin that needs Taichi annotations (``ti.template()``
for an array argument, ``ti.f64``) writes them in a module with ``from __future__ import annotations``: they
stay strings until the function is built, and are evaluated then.
"""

import functools
import importlib
import inspect


class Deferred:
    """Module ``module`` (or its attribute ``attribute``), imported on the first attribute access."""

    def __init__(self, module: str, attribute: str | None = None):
        self._module = module
        self._attribute = attribute

    def __getattr__(self, name):
        target = importlib.import_module(self._module)
        return getattr(getattr(target, self._attribute) if self._attribute else target, name)


class TaichiFunc:
    """A function as ``ti.func`` makes it, built when a kernel first calls it."""

    _is_taichi_function = True
    _is_real_function = False

    def __init__(self, fn):
        functools.update_wrapper(self, fn)

    @functools.cached_property
    def func(self):
        """Taichi's function object for the wrapped function (what ``ti.func`` keeps in ``.func``)."""
        from hfgpu.kernels.runtime import ti as taichi

        fn = self.__wrapped__
        if any(isinstance(note, str) for note in fn.__annotations__.values()):
            fn.__annotations__ = inspect.get_annotations(fn, eval_str=True)
        return taichi.func(fn).func

    def __call__(self, *args, **kwargs):
        return self.func(*args, **kwargs)


class _Taichi(Deferred):
    """hfgpu.kernels.runtime's ``ti``, with ``func`` deferred (TaichiFunc)."""

    func = staticmethod(TaichiFunc)


ti = _Taichi("hfgpu.kernels.runtime", "ti")
