"""Taichi kernel of the fluid momentum predictor (the paper, Eq. 26 / 49 with Eq. 62-65 and Eq. 9).

Same arithmetic, conventions and signature as the NumPy reference :mod:`hfgpu.proppant.momentum` (read its
module docstring; the wall-friction factor f_t is hfgpu.kernels.closures.wall_friction's): one thread per face
control volume; the z component runs the x kernel on the transposed grid. Inputs and outputs are NumPy float64 arrays.
"""


import numpy as np

from hfgpu.kernels.runtime import init, ti
from hfgpu.kernels.closures.wall_friction import wall_friction_code, wall_friction_factor

F64_2D = ti.types.ndarray(dtype=ti.f64, ndim=2)


@ti.func
def _coefficients(conductance, mass_flux):
    """(c_L, c_R) = (D A(|P|) + [F, 0], D A(|P|) + [-F, 0]), power-law A = max(0, (1 - 0.1|P|)^5) (Eq. 62)."""
    da = 0.0
    if conductance > 0.0:
        t = ti.max(0.0, 1.0 - 0.1 * ti.abs(mass_flux) / conductance)
        da = conductance * (t * t * t * t * t)
    return ti.Vector([da + ti.max(mass_flux, 0.0), da + ti.max(-mass_flux, 0.0)], dt=ti.f64)


@ti.func
def _old_q(width0: ti.template(), theta_f0: ti.template(), k, i):
    """theta_f^o w^o of cell (k, i), 0 when it was closed."""
    q = 0.0
    if width0[k, i] > 0.0:
        q = theta_f0[k, i] * width0[k, i]
    return q


@ti.kernel
def predict_x(u0: F64_2D, v0: F64_2D, p: F64_2D, width0: F64_2D, theta_f0: F64_2D, width: F64_2D,
              theta_f: F64_2D, mu: F64_2D, force_x: F64_2D, rho: ti.f64, dx: ti.f64, dz: ti.f64, dt: ti.f64,
              dean: ti.i32, u_star: F64_2D, d: F64_2D):
    """u* and d on the x-faces (Eq. 49 with Eq. 62-65, friction Eq. 9 and the u_P flux coefficients
    point-implicit, a closed corner a free-slip ghost; dean = 1: Eq. 9 times Dean's f_t); walls and closed faces
    get 0."""
    nz, nx = width.shape[0], width.shape[1]
    for k, i in ti.ndrange((0, nz), (0, nx + 1)):
        us, dd = 0.0, 0.0
        inside = 1 <= i and i <= nx - 1
        is_open = False
        if inside:
            is_open = width[k, i - 1] > 0.0 and width[k, i] > 0.0
        if is_open:
            w_f = 0.5 * (width[k, i - 1] + width[k, i])
            q_f = 0.5 * (theta_f[k, i - 1] * width[k, i - 1] + theta_f[k, i] * width[k, i])
            q0_f = 0.0
            if width0[k, i - 1] > 0.0 and width0[k, i] > 0.0:
                q0_f = 0.5 * (_old_q(width0, theta_f0, k, i - 1) + _old_q(width0, theta_f0, k, i))
            mu_f = 0.5 * (mu[k, i - 1] + mu[k, i])
            # east (cell i) and west (cell i-1) faces of the control volume
            ce = _coefficients(width0[k, i] * mu[k, i] * dz / (rho * dx),
                               _old_q(width0, theta_f0, k, i) * dz * 0.5 * (u0[k, i] + u0[k, i + 1]))
            cw = _coefficients(width0[k, i - 1] * mu[k, i - 1] * dz / (rho * dx),
                               _old_q(width0, theta_f0, k, i - 1) * dz * 0.5 * (u0[k, i - 1] + u0[k, i]))
            diag = ce[0] + cw[1]
            nb = ce[1] * u0[k, i + 1] + cw[0] * u0[k, i - 1]
            # a closed corner's free-slip ghost u_g = u_P: conductance of the face's own old width and viscosity
            ghost = 0.0
            if width0[k, i - 1] > 0.0 and width0[k, i] > 0.0:
                ghost = 0.5 * (width0[k, i - 1] + width0[k, i]) * mu_f * dx / (rho * dz)
            # north face (corner of rows k-1, k), then south face (rows k, k+1)
            for side in ti.static(range(2)):
                top = k - 1 + side
                corner = False
                if 0 <= top and top + 1 <= nz - 1:
                    corner = (width0[top, i - 1] > 0.0 and width0[top, i] > 0.0 and width0[top + 1, i - 1] > 0.0
                              and width0[top + 1, i] > 0.0)
                if corner:
                    q_c = 0.25 * (_old_q(width0, theta_f0, top, i - 1) + _old_q(width0, theta_f0, top, i)
                                  + _old_q(width0, theta_f0, top + 1, i - 1) + _old_q(width0, theta_f0, top + 1, i))
                    w_c = 0.25 * (width0[top, i - 1] + width0[top, i] + width0[top + 1, i - 1] + width0[top + 1, i])
                    mu_c = 0.25 * (mu[top, i - 1] + mu[top, i] + mu[top + 1, i - 1] + mu[top + 1, i])
                    c = _coefficients(w_c * mu_c * dx / (rho * dz),
                                      q_c * dx * 0.5 * (v0[top + 1, i - 1] + v0[top + 1, i]))
                    if ti.static(side == 0):
                        diag += c[1]
                        nb += c[0] * u0[top, i]
                    else:
                        diag += c[0]
                        nb += c[1] * u0[top + 1, i]
                else:
                    diag += ghost
                    nb += ghost * u0[k, i]
            v_f = 0.25 * (v0[k, i - 1] + v0[k, i] + v0[k + 1, i - 1] + v0[k + 1, i])
            f_t = wall_friction_factor(ti.sqrt(u0[k, i] ** 2 + v_f ** 2), w_f, mu_f, rho, dean)
            a = q_f + dt / (dx * dz) * diag + dt * 12.0 * mu_f * f_t / (rho * w_f)
            drive = w_f * (-(p[k, i] - p[k, i - 1]) / (rho * dx) - force_x[k, i] / rho)
            us = (q0_f * u0[k, i] + dt / (dx * dz) * nb + dt * drive) / a
            dd = dt * w_f / (rho * dx * a)
        u_star[k, i] = us
        d[k, i] = dd


def momentum_predictor(u0: np.ndarray, v0: np.ndarray, p: np.ndarray, width0: np.ndarray,
                       theta_f0: np.ndarray, width: np.ndarray, theta_f: np.ndarray, mu: np.ndarray,
                       force_x: np.ndarray, force_z: np.ndarray, rho: float, dx: float, dz: float,
                       dt: float, wall_friction: str = "laminar"
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Momentum predictor, Eq. 26 / 49, on Taichi; same arguments and results as
    :func:`hfgpu.proppant.momentum.momentum_predictor`."""
    dean = wall_friction_code(wall_friction)
    init()
    nz, nx = width.shape
    c = np.ascontiguousarray
    u_star, d_u = np.zeros((nz, nx + 1)), np.zeros((nz, nx + 1))
    v_star_t, d_v_t = np.zeros((nx, nz + 1)), np.zeros((nx, nz + 1))
    predict_x(c(u0), c(v0), c(p), c(width0), c(theta_f0), c(width), c(theta_f), c(mu), c(force_x),
              rho, dx, dz, dt, dean, u_star, d_u)
    predict_x(c(v0.T), c(u0.T), c(p.T), c(width0.T), c(theta_f0.T), c(width.T), c(theta_f.T), c(mu.T),
              c(force_z.T), rho, dz, dx, dt, dean, v_star_t, d_v_t)
    return u_star, v_star_t.T.copy(), d_u, d_v_t.T.copy()
