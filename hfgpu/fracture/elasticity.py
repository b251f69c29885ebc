"""Elasticity of a planar crack by piecewise-constant displacement discontinuities (Eq. 20-21).

Uniform rectangular elements of size dx x dz; the opening w_j of element j changes the normal traction at
the centre of element i by C_ij w_j, with (Crouch & Starfield 1983, Eq. 21 of the paper, written with
the sign that makes the self-influence positive)

    C_ij = E' / (8 pi) [ sqrt(X^2 + Z^2) / (X Z) ]  evaluated at X = x_i - x_j -+ dx/2, Z = z_i - z_j -+ dz/2

(the bracket is the double difference F(X+, Z+) - F(X+, Z-) - F(X-, Z+) + F(X-, Z-) over the corners),
so that p_i - sigma_i = sum_j C_ij w_j (Eq. 20). The kernel depends only on the integer offset between
cells, so on a uniform grid the operator is block-Toeplitz.
"""

from __future__ import annotations

import numpy as np


def _corner(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    return np.sqrt(x * x + z * z) / (x * z)


def influence(offset_x: np.ndarray, offset_z: np.ndarray, dx: float, dz: float,
              plane_strain_modulus: float) -> np.ndarray:
    """C for receiver-minus-source centre offsets (metres), Eq. 21. Broadcasts its arguments."""
    a, b = 0.5 * dx, 0.5 * dz
    x = np.asarray(offset_x, dtype=float)
    z = np.asarray(offset_z, dtype=float)
    bracket = (_corner(x + a, z + b) - _corner(x + a, z - b)
               - _corner(x - a, z + b) + _corner(x - a, z - b))
    return plane_strain_modulus / (8.0 * np.pi) * bracket


def dense_matrix(ix: np.ndarray, iz: np.ndarray, dx: float, dz: float,
                 plane_strain_modulus: float) -> np.ndarray:
    """The dense N x N matrix C_ij of Eq. 20 for active cells at integer indices (ix, iz): the oracle."""
    ix = np.asarray(ix)
    iz = np.asarray(iz)
    offset_x = (ix[:, None] - ix[None, :]) * dx
    offset_z = (iz[:, None] - iz[None, :]) * dz
    return influence(offset_x, offset_z, dx, dz, plane_strain_modulus)
