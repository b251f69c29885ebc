"""Particle stress and the packing limiter: the Harris & Crighton (1994) normal stress of Eq. 16 and the limiter
of the stress velocity of Snider (2001), NumPy references and Taichi twins.

tau = P_s theta_p^beta / max(theta_cp - theta_p, eps (1 - theta_p)) [Pa] (Eq. 16). The limiter (Snider 2001
eqs. 39-41, as in MFIX integrate_time_pic.f90): the stress velocity correction delta = -dt grad tau / (theta_p
rho_p ...) of the push is bounded by (1 + e) x (mean parcel velocity - parcel velocity) and may act only along
-grad tau.
"""

import numpy as np

from hfgpu.kernels.closures.twin import ti


def stress_denominator_numpy(theta_p, theta_cp, epsilon):
    """max(theta_cp - theta_p, eps (1 - theta_p)) of Eq. 16."""
    return np.maximum(theta_cp - theta_p, epsilon * (1.0 - theta_p))


def particle_stress_numpy(theta_p, p_s, beta, theta_cp, epsilon):
    """tau = P_s theta_p^beta / max(theta_cp - theta_p, eps (1 - theta_p)) [Pa] (Eq. 16)."""
    theta_p = np.asarray(theta_p, dtype=np.float64)
    return p_s * theta_p ** beta / stress_denominator_numpy(theta_p, theta_cp, epsilon)


def particle_stress_derivative_numpy(theta_p, p_s, beta, theta_cp, epsilon):
    """d tau / d theta_p of Eq. 16 (the branch of the max in use), without the beta/theta singularity."""
    theta_p = np.asarray(theta_p, dtype=np.float64)
    den = stress_denominator_numpy(theta_p, theta_cp, epsilon)
    slope = np.where(theta_cp - theta_p >= epsilon * (1.0 - theta_p), 1.0, epsilon)
    tau = p_s * theta_p ** beta / den
    return p_s * beta * theta_p ** (beta - 1.0) / den + tau * slope / den


def packing_limiter_numpy(delta, slip, grad, restitution):
    """The limited stress velocity: bound = (1 + e) slip; in [0, bound] where grad tau <= 0, in [bound, 0]
    elsewhere (Snider 2001 eqs. 39-41)."""
    bound = (1.0 + restitution) * slip
    return np.where(grad <= 0.0, np.maximum(np.minimum(delta, bound), 0.0),
                    np.minimum(np.maximum(delta, bound), 0.0))


@ti.func
def stress_denominator(theta_p, theta_cp, epsilon):
    """max(theta_cp - theta_p, eps (1 - theta_p)) of Eq. 16."""
    return ti.max(theta_cp - theta_p, epsilon * (1.0 - theta_p))


@ti.func
def particle_stress(theta_p, p_s, beta, theta_cp, epsilon):
    """tau of Eq. 16 for a scalar theta_p; 0 at theta_p = 0 without the power (beta > 0)."""
    den = stress_denominator(theta_p, theta_cp, epsilon)
    tau = 0.0
    if theta_p > 0.0:
        tau = p_s * ti.pow(theta_p, beta) / den
    return tau


@ti.func
def packing_limiter(delta, slip, grad, restitution):
    """The limited stress velocity of Snider (2001) eqs. 39-41, elementwise (packing_limiter_numpy)."""
    bound = (1.0 + restitution) * slip
    return ti.select(grad <= 0.0, ti.max(ti.min(delta, bound), 0.0), ti.min(ti.max(delta, bound), 0.0))
