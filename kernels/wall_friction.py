"""The wall-friction laws of the fluid's momentum predictor: their names, the integer code a kernel takes, and
Dean's coefficient. Plain Python (no Taichi import), shared by the NumPy reference (hfgpu.proppant.momentum,
hfgpu.proppant.params) and the kernel (hfgpu.kernels.momentum), so that both read one definition."""

#: "laminar": Eq. 9; "dean": Eq. 9 times Dean's f_t (hfgpu.proppant.momentum module docstring)
WALL_FRICTION_LAWS = ("laminar", "dean")
DEAN_COEFFICIENT = 0.073  # c_f = 0.073 Re^(-1/4), Dean (1978)


def wall_friction_code(law: str) -> int:
    """Integer code of a wall-friction law for kernels: 0 laminar (Eq. 9), 1 dean; ValueError for other names."""
    if law not in WALL_FRICTION_LAWS:
        raise ValueError(f"wall_friction {law!r} is not one of {WALL_FRICTION_LAWS}")
    return WALL_FRICTION_LAWS.index(law)
