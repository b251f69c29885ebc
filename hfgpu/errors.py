"""Exceptions with messages a user can act on."""

from __future__ import annotations


class HfgpuError(Exception):
    """Base class of every error hfgpu raises on purpose."""


SHOWN_VALUE = 32   # characters of a bad value's repr a SceneError shows


class SceneError(HfgpuError, ValueError):
    """A scene value is missing, malformed or out of range.

    The message names the key path (``rock.layers[1].min_stress``), the value found and what is allowed.
    """

    def __init__(self, path: str, value: object, allowed: str):
        self.path = path
        self.value = value
        self.allowed = allowed
        shown = "(missing)" if value is _MISSING else repr(value)
        if len(shown) > SHOWN_VALUE:   # a long value (a pasted table, a stray string) would bury the message
            shown = shown[:SHOWN_VALUE - 3] + "..."
        super().__init__(f"scene key '{path}': got {shown}; {allowed}")


class SimulationError(HfgpuError, RuntimeError):
    """A run could not continue (Newton failed after retries, NaN, CFL broken beyond recovery).

    Carries the simulated time and, where known, the cell and residual that failed.
    """

    def __init__(self, message: str, *, time: float | None = None, cell: object = None,
                 residual: float | None = None):
        self.time = time
        self.cell = cell
        self.residual = residual
        detail = []
        if time is not None:
            detail.append(f"t = {time:.6g} s")
        if cell is not None:
            detail.append(f"cell {cell}")
        if residual is not None:
            detail.append(f"residual {residual:.3e}")
        super().__init__(message + (f" ({', '.join(detail)})" if detail else ""))


class _Missing:
    def __repr__(self) -> str:
        return "(missing)"


_MISSING = _Missing()
MISSING = _MISSING
