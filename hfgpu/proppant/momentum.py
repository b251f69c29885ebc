"""Momentum predictor of the MP-PIC fluid phase, NumPy reference (the paper, Eq. 26 / 49, 62-65).

For each open face control volume (x-faces for u, z-faces for v; layout in :mod:`hfgpu.proppant.grid`) the
convection-diffusion flux through each of its four faces is Eq. 62-65,

    J = c_L u_L - c_R u_R,   c_L = D A(|P|) + [F, 0],   c_R = D A(|P|) + [-F, 0],

with the power-law scheme A(|P|) = max(0, (1 - 0.1|P|)^5), Peclet number P = F/D, F and D from the old
velocities (Eq. 50-57). The predicted velocity solves Eq. 49 with the wall friction of Eq. 9 (F_w =
12 mu_f u/(rho_f w^2) f_t, opposing the flow):

    a_P u*_P = (theta_f^o w^o)_P u^o_P + dt/(dx dz) sum_nb c_nb u^o_nb
               + dt w_P ( (p_W - p_E)/(rho_f dx) - F_x/rho_f ),
    a_P = (theta_f w)_P + dt/(dx dz) sum_faces c_P + dt 12 mu_f,P f_t,P / (rho_f w_P).

f_t is the wall-friction factor of ``wall_friction`` (hfgpu.kernels.closures.wall_friction: 1 for "laminar",
Dean's turbulent friction for "dean"), from the old speed |U| = (u^2 + v^2)^(1/2) at the face (v on an x-face:
the mean of its four v-faces), so f_t is lagged and the friction stays point-implicit.

Two terms are taken at the new level, point-implicitly (no linear system): the friction, and the u_P
coefficients c_P of the fluxes. Why: explicitly the friction limits the step to dt < rho_f w^2/(12 mu_f)
(0.08 s for water in a 1 mm gap, 1e-3 s for a 100 cP gel) and the in-plane viscous flux to
dt < rho_f theta_f / (2 mu_f (1/dx^2 + 1/dz^2)), which goes to 0 where Eq. 10's slurry viscosity diverges
near close packing. With both on the diagonal every coefficient is positive and the update is (up to the
control volume's own continuity defect) a weighted mean of old values, so neither limit applies (the
Courant limit Eq. 42 still bounds dt, for the convective part and the particles); neighbours stay explicit
as in the paper, and a steady state is exactly plane Poiseuille flow, u = -w^2/(12 mu_f) dp/dx. The
pressure-correction coefficient d_P = dt w_P/(rho_f dx a_P) (u = u* + d_P (p'_W - p'_E)) is returned with u*.

Conventions: (theta_f w) at a face is the mean of its two cells (0 unless both are open); at a corner of four cells
(the z-faces of a u control volume) the mean of the four cells when all are open. A corner that is not (on the
domain's walls, beside closed cells) is free-slip for the in-plane viscous stress (the wall friction of the
fracture faces is F_w): its neighbour is the mirror ghost u_g = u_P, taken as the open corners' neighbours are, at
the old level, with the conductance of the face's own old width and viscosity, D_g = w^o_f mu_f dx/(rho_f dz),
added to sum c_P and D_g u^o_P to sum c_nb u^o_nb. Its flux D_g (u^o_P - u_P) vanishes in a steady state, as free
slip must, and gives the point-implicit lag of a face on a wall the same weight as inside, so that a flow uniform
along a wall stays uniform: without the ghost a face on a wall lags less while the flow changes (a settling
suspension's backflow under its falling interface), and the difference drives a circulation along the walls
(tests/proppant/test_momentum.py). u at a cell centre is the mean of its two faces. The diffusion conductance D = w
mu_f dy/(rho_f delta) (Eq. 50-53, delta = the grid spacing) uses the old width. Walls and closed faces have u = 0.
The z component is the same computation on the transposed grid.
"""

from __future__ import annotations

import numpy as np

from ..kernels.closures.wall_friction import wall_friction_code, wall_friction_factor_numpy
from .grid import face_mean


def face_coefficients(conductance: np.ndarray, mass_flux: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(c_L, c_R) of the face flux J = c_L u_L - c_R u_R (Eq. 62): c_L = D A(|P|) + [F, 0], c_R = D A(|P|) +
    [-F, 0] with the power-law A(|P|) = max(0, (1 - 0.1|P|)^5), P = F/D (Patankar 1980, section 5.2);
    D A = 0 where D = 0."""
    safe = np.where(conductance > 0.0, conductance, 1.0)
    a = np.maximum(0.0, 1.0 - 0.1 * np.abs(mass_flux) / safe) ** 5
    da = np.where(conductance > 0.0, conductance * a, 0.0)
    return da + np.maximum(mass_flux, 0.0), da + np.maximum(-mass_flux, 0.0)


def _predict_x(u0, v0, p, width0, theta_f0, width, theta_f, mu, force_x, rho, dx, dz, dt, wall_friction):
    """u* and d on the x-faces (Eq. 49 with Eq. 62-65 and Eq. 9); see the module docstring."""
    nz, nx = width.shape
    open0, open1 = width0 > 0.0, width > 0.0
    q0 = np.where(open0, theta_f0 * width0, 0.0)
    # face (x) quantities on the interior faces i = 1 .. nx-1
    face = open1[:, :-1] & open1[:, 1:]
    w_f = np.where(face, face_mean(width, open1, axis=1)[:, 1:-1], 1.0)
    q_f = face_mean(theta_f * width, open1, axis=1)[:, 1:-1]
    q0_f = face_mean(q0, open0, axis=1)[:, 1:-1]
    mu_f = 0.5 * (mu[:, :-1] + mu[:, 1:])
    # east/west faces of the u control volumes = cell centres (Eq. 50-51, 62-63)
    f_c = q0 * dz * 0.5 * (u0[:, :-1] + u0[:, 1:])
    d_c = width0 * mu * dz / (rho * dx)
    cl, cr = face_coefficients(d_c, f_c)
    diag = cl[:, 1:] + cr[:, :-1]
    nb = cr[:, 1:] * u0[:, 2:] + cl[:, :-1] * u0[:, :-2]
    # south/north faces = corners of four cells (Eq. 52-53, 64-65); a closed corner is a free-slip ghost
    u_in = u0[:, 1:-1]
    ghost = face_mean(width0, open0, axis=1)[:, 1:-1] * mu_f * dx / (rho * dz)
    walls = np.full((nz, nx - 1), 2.0)      # closed corners of each face control volume, north and south
    if nz > 1 and nx > 1:
        corner = open0[:-1, :-1] & open0[:-1, 1:] & open0[1:, :-1] & open0[1:, 1:]
        q_c = 0.25 * (q0[:-1, :-1] + q0[:-1, 1:] + q0[1:, :-1] + q0[1:, 1:])
        w_c = 0.25 * (width0[:-1, :-1] + width0[:-1, 1:] + width0[1:, :-1] + width0[1:, 1:])
        mu_c = 0.25 * (mu[:-1, :-1] + mu[:-1, 1:] + mu[1:, :-1] + mu[1:, 1:])
        f_z = np.where(corner, q_c, 0.0) * dx * 0.5 * (v0[1:-1, :-1] + v0[1:-1, 1:])
        d_z = np.where(corner, w_c, 0.0) * mu_c * dx / (rho * dz)
        cl_z, cr_z = face_coefficients(d_z, f_z)
        diag[1:] += cr_z      # north face of rows 1.. (P below the corner)
        diag[:-1] += cl_z     # south face of rows ..nz-2 (P above the corner)
        nb[1:] += cl_z * u_in[:-1]
        nb[:-1] += cr_z * u_in[1:]
        walls[1:] -= corner
        walls[:-1] -= corner
    diag += walls * ghost
    nb += walls * ghost * u_in
    v_f = 0.25 * (v0[:-1, :-1] + v0[:-1, 1:] + v0[1:, :-1] + v0[1:, 1:])  # v at the x-faces
    f_t = wall_friction_factor_numpy(np.sqrt(u0[:, 1:-1] ** 2 + v_f ** 2), w_f, mu_f, rho,
                                     wall_friction_code(wall_friction))
    a = q_f + dt / (dx * dz) * diag + dt * 12.0 * mu_f * f_t / (rho * w_f)
    drive = w_f * (-(p[:, 1:] - p[:, :-1]) / (rho * dx) - force_x[:, 1:-1] / rho)
    rhs = q0_f * u0[:, 1:-1] + dt / (dx * dz) * nb + dt * drive
    safe_a = np.where(face, a, 1.0)
    u_star = np.zeros((nz, nx + 1))
    d = np.zeros((nz, nx + 1))
    u_star[:, 1:-1] = np.where(face, rhs / safe_a, 0.0)
    d[:, 1:-1] = np.where(face, dt * w_f / (rho * dx * safe_a), 0.0)
    return u_star, d


def momentum_predictor(u0: np.ndarray, v0: np.ndarray, p: np.ndarray, width0: np.ndarray,
                       theta_f0: np.ndarray, width: np.ndarray, theta_f: np.ndarray, mu: np.ndarray,
                       force_x: np.ndarray, force_z: np.ndarray, rho: float, dx: float, dz: float,
                       dt: float, wall_friction: str = "laminar"
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Momentum predictor, Eq. 26 / 49 (NumPy reference of ``kernels/momentum.py``).

    u0 (nz, nx+1), v0 (nz+1, nx): old face velocities [m/s]; p (nz, nx): guessed dynamic pressure p* [Pa];
    width0/theta_f0 and width/theta_f (nz, nx): old and new width [m] and fluid volume fraction; mu (nz, nx):
    slurry viscosity [Pa s] (Eq. 10); force_x (nz, nx+1), force_z (nz+1, nx): interphase force F on the
    faces [N/m^3] (Eq. 8, acting on the fluid as -F); rho: fluid density [kg/m^3]; wall_friction: "laminar"
    (Eq. 9) or "dean" (Eq. 9 times f_t past the transition, module docstring).
    Returns (u*, v*, d_u, d_v): predicted face velocities and pressure-correction coefficients
    [m^3 s/kg]; 0 on walls and closed faces.
    """
    u_star, d_u = _predict_x(u0, v0, p, width0, theta_f0, width, theta_f, mu, force_x, rho, dx, dz, dt,
                             wall_friction)
    v_star_t, d_v_t = _predict_x(v0.T, u0.T, p.T, width0.T, theta_f0.T, width.T, theta_f.T, mu.T,
                                 force_z.T, rho, dz, dx, dt, wall_friction)
    return u_star, v_star_t.T.copy(), d_u, d_v_t.T.copy()
