"""The MP-PIC closures by family, as OpenFOAM's MPPIC submodels are organised: one module per family, each
holding the NumPy reference (``<name>_numpy``, float64 arrays) and its Taichi twin (``<name>``, a Taichi
function) side by side, with the equation in the docstring; the twins' tests are tests/kernels/test_closure_*.py.

drag: Eq. 13-15, "wen-yu" (Eq. 14) or "snider" (Snider 2001); particle_stress: Harris & Crighton (1994) stress
(Eq. 16) and the packing limiter of Snider (2001); damping: collision damping, O'Rourke & Snider (2010).
Importing a family does not start Taichi (twin.taichi_func), so the NumPy engine runs without it.
"""
