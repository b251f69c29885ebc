"""Wall friction of the slurry between the fracture faces: the factor f_t on the laminar friction of Eq. 9
(F_w = 12 mu_f u / (rho_f w^2) f_t), NumPy reference and Taichi twin, with the laws' names and codes.

"laminar": f_t = 1 (Eq. 9). "dean": the friction past the laminar-turbulent transition of the flow between the
faces, Dean's (1978, J. Fluids Eng. 100, 215) skin friction of smooth plane-channel flow, c_f = tau_w /
(rho_f U^2 / 2) = 0.073 Re^(-1/4), Re = rho_f |U| w / mu_f (bulk velocity, full gap); the gap-averaged friction
per unit volume 2 tau_w / w = c_f rho_f |U| U / w, and the laminar c_f = 12 / Re gives Eq. 9, so

    f_t = max(1, c_f Re / 12) = max(1, (0.073 / 12) Re^(3/4))

(the two laws cross at Re = (12 / 0.073)^(4/3) = 899). The fluid's momentum predictor (hfgpu.proppant.momentum,
hfgpu.kernels.momentum) and the bed shear stress of the threshold of motion (closures.bed) use it.
"""

import numpy as np

from hfgpu.kernels.closures.twin import ti

#: the laws' names; a kernel takes the index (wall_friction_code)
WALL_FRICTION_LAWS = ("laminar", "dean")
DEAN_COEFFICIENT = 0.073  # c_f = 0.073 Re^(-1/4), Dean (1978)


def wall_friction_code(law: str) -> int:
    """Integer code of a wall-friction law for kernels: 0 laminar (Eq. 9), 1 dean; ValueError for other names."""
    if law not in WALL_FRICTION_LAWS:
        raise ValueError(f"wall_friction {law!r} is not one of {WALL_FRICTION_LAWS}")
    return WALL_FRICTION_LAWS.index(law)


def wall_friction_factor_numpy(speed, width, mu, rho, code: int):
    """f_t (module docstring) of law ``code`` at speed |U| [m/s], width w [m], viscosity mu [Pa s], density rho."""
    if code == 0:
        return np.ones(np.broadcast(speed, width, mu).shape)
    return np.maximum(1.0, DEAN_COEFFICIENT / 12.0 * (rho * speed * width / mu) ** 0.75)


@ti.func
def wall_friction_factor(speed, width, mu, rho, code):
    """f_t (module docstring) for scalar inputs; ``code`` 1 is "dean", any other value "laminar"."""
    f_t = 1.0
    if code == 1:
        f_t = ti.max(1.0, DEAN_COEFFICIENT / 12.0 * (rho * speed * width / mu) ** 0.75)
    return f_t
