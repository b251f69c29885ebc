"""Taichi kernels of hfgpu, installed as ``hfgpu.kernels`` (the PyPI name ``kernels`` is someone else's).

``import taichi`` happens in :mod:`hfgpu.kernels.runtime` only; every kernel here has a NumPy reference
in :mod:`hfgpu.proppant` and a CPU-backend test that compares them.
"""
