"""Collision damping, O'Rourke & Snider (2010) eq. 48: the damping rate 1/tau_D [1/s] that relaxes a parcel
towards its cell's mean parcel velocity, NumPy reference and Taichi twin.

1/tau_D = (16 / sqrt(3 pi)) theta_p sigma / r32 g0 eta (1 - eta), eta = (1 + e) / 2, sigma the square root of
the cell's velocity variance, r32 its Sauter radius, g0 = theta_cp / max(theta_cp - theta_p, eps (1 - theta_p))
(the denominator of Eq. 16) floored at 1 (MFIX). Zero where damping is off, where theta_p <= damping_threshold x
theta_cp (the paper: damping acts in the packed bed only) or where r32 = 0.
"""

import numpy as np

from hfgpu.kernels.closures.particle_stress import stress_denominator, stress_denominator_numpy
from hfgpu.kernels.closures.twin import ti

SQRT_3PI = 3.0699801238394655  # sqrt(3 pi)
#: How the push applies the rate h = 1/(2 tau_D) (particle_ops_numpy.push, kernels/particles.py velocity_lanes):
#: "implicit" = O'Rourke & Snider (2010), u = (u^o + dt (D u_f + a + h <u>)) / (1 + dt (D + h)), the cell's mean
#: <u> from the step before; "relaxation" = the old velocity relaxed towards <u>, u^o + dt h / (1 + dt h)
#: (<u> - u^o), then the drag step with 1 + dt D, which keeps the cell's mean answer to drag and gravity
#: (docs/proppant-closures.md, "Collision damping in a dense cell").
DAMPING_SCHEMES = ("implicit", "relaxation")


def damping_rate_numpy(theta_p, velocity_variance, sauter_radius, enabled, restitution, threshold, theta_cp,
                       epsilon):
    """1/tau_D [1/s] (module docstring); ``enabled`` false gives zeros."""
    theta_p = np.asarray(theta_p, dtype=np.float64)
    if not enabled:
        return np.zeros_like(theta_p)
    eta = 0.5 * (1.0 + restitution)
    g0 = np.maximum(1.0, theta_cp / stress_denominator_numpy(theta_p, theta_cp, epsilon))
    sigma = np.sqrt(np.maximum(velocity_variance, 0.0))
    active = (theta_p > threshold * theta_cp) & (sauter_radius > 0.0)
    safe_r = np.where(active, sauter_radius, 1.0)
    rate = 16.0 / SQRT_3PI * theta_p * sigma / safe_r * g0 * eta * (1.0 - eta)
    return np.where(active, rate, 0.0)


@ti.func
def damping_rate(theta_p, velocity_variance, sauter_radius, enabled, restitution, threshold, theta_cp, epsilon):
    """1/tau_D for scalar inputs (module docstring); ``enabled`` > 0 switches damping on."""
    rate = 0.0
    if enabled > 0.0 and theta_p > threshold * theta_cp and sauter_radius > 0.0:
        eta = 0.5 * (1.0 + restitution)
        g0 = ti.max(1.0, theta_cp / stress_denominator(theta_p, theta_cp, epsilon))
        sigma = ti.sqrt(ti.max(velocity_variance, 0.0))
        rate = 16.0 / SQRT_3PI * theta_p * sigma / sauter_radius * g0 * eta * (1.0 - eta)
    return rate
