"""Slurry viscosity: the viscosity the fluid phase sees in a cell of solid volume fraction theta_p, NumPy
reference. The fluid (SIMPLE, hfgpu.proppant.fluid) evaluates it on the host once per fluid step from the
scattered theta_p, so it has no Taichi twin: no kernel reads it.

    "power":             mu = mu_o (1 - theta_p / theta_cp)^n             (the paper, Eq. 10, after Barree
                                                                          & Conway; n = -1.82)
    "krieger-dougherty": mu = mu_o (1 - theta_p / theta_cp)^(-2.5 theta_cp)   (Krieger & Dougherty 1959)

Both diverge at close packing; mu / mu_o is capped at ``max_relative`` so the viscosity stays finite at and
beyond theta_cp (the base 1 - theta_p / theta_cp is floored at max_relative^(1/exponent)).
"""

import numpy as np

#: the laws' names (MppicParams.viscosity_law)
VISCOSITY_LAWS = ("power", "krieger-dougherty")


def exponent(law: str, power_exponent: float, theta_cp: float) -> float:
    """The law's exponent: ``power_exponent`` (n) for "power", -2.5 theta_cp for "krieger-dougherty"."""
    if law not in VISCOSITY_LAWS:
        raise ValueError(f"viscosity_law {law!r} is not one of {VISCOSITY_LAWS}")
    return power_exponent if law == "power" else -2.5 * theta_cp


def slurry_viscosity_numpy(theta_p, fluid_viscosity, law: str, power_exponent: float, theta_cp: float,
                           max_relative: float):
    """mu [Pa s] of the slurry (module docstring) for the clean-fluid viscosity mu_o = ``fluid_viscosity``."""
    n = exponent(law, power_exponent, theta_cp)
    base = np.maximum(1.0 - np.asarray(theta_p, dtype=np.float64) / theta_cp, max_relative ** (1.0 / n))
    return fluid_viscosity * base ** n
