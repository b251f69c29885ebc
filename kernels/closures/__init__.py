"""The MP-PIC closures by family, as OpenFOAM's MPPIC submodels are organised: one module per family, each
holding the NumPy reference (``<name>_numpy``, float64 arrays) and its Taichi twin (``<name>``, a Taichi
function) side by side, with the equation in the docstring; the twins' tests are tests/kernels/test_closure_*.py.

drag: Eq. 13-15, "wen-yu" (Eq. 14) or "snider" (Snider 2001); particle_stress: Harris & Crighton (1994) stress
(Eq. 16) and the packing limiter of Snider (2001); damping: collision damping, O'Rourke & Snider (2010).
walls: what stops a parcel's move (leaving the grid, a closed cell, a cell narrower than the bridging gap, a
raised weight on a packed cell, a dense cell's move towards a wall), on positions (NumPy) or cell coordinates.
bed: Coulomb bed friction on the grain's own weight or on the overburden, "grain" or "overburden" (Johnson &
Jackson 1987), and the threshold of motion (Shields 1936; Soulsby & Whitehouse 1997);
averaging: the volume fraction a parcel sees, "dual", "basic" or "moment" (OpenFOAM's AveragingMethods);
wall_friction: the factor f_t on Eq. 9's friction, "laminar" or "dean" (Dean 1978); slurry_viscosity: Eq. 10 or
Krieger & Dougherty (1959), NumPy only (the fluid evaluates it on the host).
Importing a family does not start Taichi (twin.py), so the NumPy engine runs without it.
"""
