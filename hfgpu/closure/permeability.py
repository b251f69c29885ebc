"""Permeability of a proppant pack: Kozeny-Carman from its grains, or a vendor's conductivity table.

Kozeny-Carman (Carman 1937, Trans. Inst. Chem. Eng. 15, 150; Bear 1972, Dynamics of Fluids in Porous Media,
eq. 5.10.18) for a pack of spheres of diameter d and porosity phi = 1 - phi_s:

    k = d^2 phi^3 / (180 (1 - phi)^2)

with d the Sauter mean diameter d_32 = sum V / sum (V / d) of the grains in the cell (the diameter of equal
specific surface, which the Kozeny-Carman derivation rests on), so a mix of sizes gives the permeability of its
mix.

Tables (API RP 19D / ISO 13503-5 long-term conductivity, as vendors publish them): conductivity C_i [m^3]
against closure stress sigma_i, interpolated log-linearly (ln C linear in sigma) and held at the end nodes'
values outside the table. The lab pack is loaded with ``loading`` kg/m^2 (2 lb/ft^2 by default) of grains of
density rho_p at the pack solid fraction phi_s, so its width is w_lab = loading / (rho_p phi_s) and the pack's
permeability k = C(sigma) / w_lab; a table of permeabilities gives k(sigma) directly.
"""

from __future__ import annotations

import numpy as np

from .config import ConductivityTable


def kozeny_carman(diameter: np.ndarray, porosity: float) -> np.ndarray:
    """k = d^2 phi^3 / (180 (1 - phi)^2) [m^2] for grain diameter(s) d [m] and porosity phi."""
    d = np.asarray(diameter, dtype=np.float64)
    return d**2 * porosity**3 / (180.0 * (1.0 - porosity) ** 2)


def interpolate_log(table: ConductivityTable, stress: np.ndarray) -> np.ndarray:
    """The table's value at ``stress`` [Pa]: exp of the linear interpolation of ln(value) in stress, the end
    values outside the table's range."""
    return np.exp(np.interp(np.asarray(stress, dtype=np.float64), table.stress, np.log(table.value)))


def table_permeability(table: ConductivityTable, stress: np.ndarray, density: float, loading: float,
                       pack_fraction: float) -> np.ndarray:
    """k(sigma) [m^2] of a class from its table: the value itself for a permeability table, else
    C(sigma) / w_lab with w_lab = loading / (density pack_fraction) [m]."""
    value = interpolate_log(table, stress)
    return value if table.is_permeability else value * density * pack_fraction / loading
