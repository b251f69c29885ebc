"""Measurements on MP-PIC results used by validations and demos: interface depths of a settling column and
the proppant bank of a slot."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..records import GridFrame
from .parcels import Parcels
from .particle_ops_numpy import finish_moments, moment_sums


def class_volume_fraction(parcels: Parcels, frame: GridFrame, width: np.ndarray, class_id: int) -> np.ndarray:
    """theta_p (nz, nx) of the parcels of one class (Eq. 38 on that class alone, NumPy scatter)."""
    subset = parcels.copy()
    subset.drop(subset.class_id != class_id)
    return finish_moments(moment_sums(subset, frame, width), frame, width).volume_fraction


def row_profile(volume_fraction: np.ndarray, width: np.ndarray) -> np.ndarray:
    """Width-weighted mean of theta_p over each row (nz): the volume fraction profile of a column."""
    w = np.where(width > 0.0, width, 0.0)
    return np.sum(volume_fraction * w, axis=1) / np.maximum(np.sum(w, axis=1), 1e-300)


def interface_depth(profile: np.ndarray, frame: GridFrame, level: float) -> float:
    """Depth [m] where a column profile first rises through ``level`` going down from the top, linearly
    interpolated between cell centres (the top of the domain if the first cell is already above it)."""
    z = frame.z0 + frame.dz * np.arange(profile.size)
    above = np.nonzero(profile >= level)[0]
    if above.size == 0:
        return float(z[-1] + 0.5 * frame.dz)
    k = int(above[0])
    if k == 0:
        return float(z[0] - 0.5 * frame.dz)
    a, b = profile[k - 1], profile[k]
    return float(z[k - 1] + (level - a) / (b - a) * frame.dz)


def fitted_speed(times, depths) -> float:
    """Least-squares slope d(depth)/dt [m/s] (positive = moving down)."""
    return float(np.polyfit(np.asarray(times, float), np.asarray(depths, float), 1)[0])


@dataclass(frozen=True)
class Bank:
    """The proppant bank (settled bed) of a slot.

    The bank is the set of cells whose theta_p >= ``threshold`` (e.g. half of close packing: a cell at least
    half-full of packed sand). ``length`` [m]: the x-extent of the columns holding bank cells (count of such
    columns x dx); ``area`` [m^2]: the bank cells' area (count x dx dz); the normalised values divide by the
    slot length and the slot area, as the GEOS digitisation of Chun et al. (2020).
    """

    length: float
    area: float
    normalised_length: float
    normalised_area: float


def bank(volume_fraction: np.ndarray, width: np.ndarray, frame: GridFrame, threshold: float) -> Bank:
    """Bank length and area of a theta_p field (see :class:`Bank`)."""
    is_bank = (volume_fraction >= threshold) & (width > 0.0)
    columns = int(np.count_nonzero(is_bank.any(axis=0)))
    cells = int(np.count_nonzero(is_bank))
    nz, nx = volume_fraction.shape
    length, area = columns * frame.dx, cells * frame.dx * frame.dz
    return Bank(length=length, area=area, normalised_length=length / (nx * frame.dx),
                normalised_area=area / (nx * nz * frame.dx * frame.dz))


def bed_height(volume_fraction: np.ndarray, width: np.ndarray, frame: GridFrame, threshold: float) -> np.ndarray:
    """Bed height [m] above the bottom of the grid in each column (nx): the bank cells (theta_p >= threshold)
    of the column times dz (the paper's Fig. 10 bed profiles)."""
    is_bank = (volume_fraction >= threshold) & (width > 0.0)
    return np.count_nonzero(is_bank, axis=0) * frame.dz


def alternation(volume_fraction: np.ndarray, dense: float = 0.4, by: float = 0.05) -> tuple[int, float]:
    """How far a bed's packing alternates from cell to cell: the number of dense cells (theta_p >= ``dense``, both
    neighbours along x too) and the share of them that are a local extreme of theta_p along x by more than
    ``by`` (theta_i - max(theta_i-1, theta_i+1) > by, or min(...) - theta_i > by)."""
    centre, left, right = volume_fraction[:, 1:-1], volume_fraction[:, :-2], volume_fraction[:, 2:]
    cells = (centre >= dense) & (left >= dense) & (right >= dense)
    extreme = (centre - np.maximum(left, right) > by) | (np.minimum(left, right) - centre > by)
    return int(cells.sum()), float((extreme & cells).sum() / max(cells.sum(), 1))
