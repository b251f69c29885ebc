"""The 2-D staggered grid of the MP-PIC fluid phase (the paper, section 3.2.1, Fig. 3).

Cell-centred arrays are (nz, nx), row 0 at depth z0, column 0 at x0 (the centre of cell [0, 0]); depth z is
positive downward. x-face velocity u is (nz, nx+1), face (k, i) between cells (k, i-1) and (k, i); z-face
velocity v is (nz+1, nx), face (k, i) between cells (k-1, i) and (k, i). The width field ``width`` (nz, nx) [m]
is the local fracture aperture; 0 marks a closed cell (no fluid). A face is open when both its cells are open
(boundary faces of the domain are walls), and its width is the mean of the two cell widths.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..errors import SceneError
from ..records import GridFrame


def face_mean(values: np.ndarray, is_open: np.ndarray, axis: int) -> np.ndarray:
    """Mean of a cell field over the two cells of each face normal to ``axis`` (1: x-faces, 0: z-faces).

    Returns the full face array ((nz, nx+1) for axis 1, (nz+1, nx) for axis 0) with 0 on boundary faces and on
    faces next to a closed cell (``is_open`` False).
    """
    values = np.moveaxis(np.asarray(values, dtype=np.float64), axis, 0)
    is_open = np.moveaxis(is_open, axis, 0)
    out = np.zeros((values.shape[0] + 1,) + values.shape[1:])
    both = is_open[:-1] & is_open[1:]
    out[1:-1] = np.where(both, 0.5 * (values[:-1] + values[1:]), 0.0)
    return np.moveaxis(out, 0, axis)


@dataclass(frozen=True, eq=False)
class StaggeredGrid:
    """Uniform staggered grid with a per-cell width (aperture) field; immutable.

    Derived arrays (face widths, masks, volumes) are computed once on first use. A growing fracture gets a
    new grid from :meth:`with_width` each step; the fluid solver keeps the previous width as w^o (Eq. 25-26).
    """

    frame: GridFrame
    width: np.ndarray = field(repr=False)

    def __post_init__(self):
        w = np.array(self.width, dtype=np.float64)
        if w.ndim != 2 or min(w.shape) < 1:
            raise SceneError("grid.width", w.shape, "must be a 2-D (nz, nx) array with nz, nx >= 1")
        if not np.all(np.isfinite(w)) or np.any(w < 0.0):
            bad = w[~(np.isfinite(w) & (w >= 0.0))].flat[0]
            raise SceneError("grid.width", float(bad), "widths must be finite and >= 0 (0 = closed cell)")
        for name in ("dx", "dz"):
            value = getattr(self.frame, name)
            if not (np.isfinite(value) and value > 0.0):
                raise SceneError(f"grid.frame.{name}", value, "must be a finite length > 0 [m]")
        w.setflags(write=False)
        object.__setattr__(self, "width", w)

    # -- constructors ---------------------------------------------------------------------------------

    @classmethod
    def box(cls, length: float, height: float, gap: float, nx: int, nz: int,
            x_left: float = 0.0, top: float = 0.0) -> "StaggeredGrid":
        """Closed vessel [x_left, x_left+length] x [top, top+height] of uniform gap [m], nx x nz cells."""
        for name, value in (("nx", nx), ("nz", nz)):
            if int(value) != value or value < 1:
                raise SceneError(f"grid.{name}", value, "must be an integer >= 1")
        for name, value in (("length", length), ("height", height), ("gap", gap)):
            if not (np.isfinite(value) and value > 0.0):
                raise SceneError(f"grid.{name}", value, "must be a finite length > 0 [m]")
        dx, dz = length / nx, height / nz
        frame = GridFrame(dx=dx, dz=dz, x0=x_left + 0.5 * dx, z0=top + 0.5 * dz)
        return cls(frame, np.full((int(nz), int(nx)), float(gap)))

    @classmethod
    def slot(cls, length: float, height: float, gap: float, nx: int, nz: int,
             x_left: float = 0.0, top: float = 0.0) -> "StaggeredGrid":
        """A slot: the same closed vessel as :meth:`box`; its inlets (sources) and outlets (fixed-pressure
        cells) are given to :meth:`hfgpu.proppant.fluid.FluidSolver.step` by the caller."""
        return cls.box(length, height, gap, nx, nz, x_left, top)

    @classmethod
    def from_width(cls, frame: GridFrame, width: np.ndarray) -> "StaggeredGrid":
        """Arbitrary width map (nz, nx) [m] on ``frame``; 0 = closed cell (e.g. outside a fracture)."""
        return cls(frame, width)

    def with_width(self, width: np.ndarray) -> "StaggeredGrid":
        """The same frame with a new width field (cells that open join the fluid grid)."""
        new = StaggeredGrid(self.frame, width)
        if new.shape != self.shape:
            raise SceneError("grid.width", new.shape, f"must keep the grid shape {self.shape}")
        return new

    # -- derived arrays -------------------------------------------------------------------------------

    @property
    def shape(self) -> tuple[int, int]:
        """(nz, nx)."""
        return self.width.shape

    @property
    def nz(self) -> int:
        return self.width.shape[0]

    @property
    def nx(self) -> int:
        return self.width.shape[1]

    @cached_property
    def active(self) -> np.ndarray:
        """(nz, nx) True where the cell is open (width > 0)."""
        return self.width > 0.0

    @cached_property
    def width_u(self) -> np.ndarray:
        """(nz, nx+1) x-face widths [m]; 0 on walls and next to closed cells."""
        return face_mean(self.width, self.active, axis=1)

    @cached_property
    def width_v(self) -> np.ndarray:
        """(nz+1, nx) z-face widths [m]; 0 on walls and next to closed cells."""
        return face_mean(self.width, self.active, axis=0)

    @cached_property
    def active_u(self) -> np.ndarray:
        """(nz, nx+1) True on open x-faces."""
        return self.width_u > 0.0

    @cached_property
    def active_v(self) -> np.ndarray:
        """(nz+1, nx) True on open z-faces."""
        return self.width_v > 0.0

    @property
    def cell_area(self) -> float:
        """dx dz [m^2]."""
        return self.frame.dx * self.frame.dz

    @cached_property
    def cell_volume(self) -> np.ndarray:
        """(nz, nx) dx dz w [m^3]."""
        return self.cell_area * self.width

    @cached_property
    def volume_u(self) -> np.ndarray:
        """(nz, nx+1) x-face control volumes dx dz w_face [m^3]."""
        return self.cell_area * self.width_u

    @cached_property
    def volume_v(self) -> np.ndarray:
        """(nz+1, nx) z-face control volumes dx dz w_face [m^3]."""
        return self.cell_area * self.width_v

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """(x, z) cell-centre coordinates, each 1-D."""
        return self.frame.centres(self.nz, self.nx)
