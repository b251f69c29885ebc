"""The wellbore between the surface and the perforations: the surface treating pressure (STP) from the bottom-hole
treating pressure (BHTP, the fluid pressure in the perforated cell), for the optional scene section ``[wellbore]``
(docs/scene.md):

    STP = BHTP - rho_s g D + dp_f

rho_s = rho_f (1 - phi) + rho_p phi is the density of the slurry pumped at that time (phi its proppant volume
fraction from the schedule; clean fluid in shut-in): the column is taken as full of it, its displacement down the
pipe is not tracked. D is the perforation depth (``[injection] depth``, true vertical). dp_f is the pipe friction
over the measured depth L, zero when the pumps stop:

    dp_f = G L                              with ``friction_gradient`` G given, else (Fanning, smooth pipe)
    dp_f = 2 f rho_s v^2 L / d              v = Q / (pi d^2 / 4), Re = rho_s v d / mu,
    f = 16 / Re (Re < 2100),  f = 0.0791 Re^(-1/4) (Blasius, Re >= 2100)

with Q the slurry rate, d the ``inner_diameter`` and mu the clean fluid's viscosity. Blasius is the friction of
a Newtonian fluid in a smooth pipe; a friction-reduced slickwater or a gel has a fraction of it: give its
measured ``friction_gradient`` then.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from typing import Any, Callable

import numpy as np

from .errors import MISSING, SceneError
from .scene_reader import Table, scene_system
from .units import display_text

GRAVITY = 9.81
#: Reynolds number above which the Blasius friction factor is used.
TURBULENT_RE = 2100.0


@dataclass(frozen=True)
class Wellbore:
    """``[wellbore]``: ``measured_depth`` L [m] of the pipe to the perforations, ``inner_diameter`` d [m] (None
    when ``friction_gradient`` is given) and ``friction_gradient`` G [Pa/m] (None: Fanning with Blasius)."""

    measured_depth: float
    inner_diameter: float | None = None
    friction_gradient: float | None = None


def parse_wellbore(t: Table, perforation_depth: float) -> Wellbore:
    """``[wellbore]`` of a scene whose perforations are at ``perforation_depth`` [m] (true vertical); an error
    quotes that depth in the scene's units (:func:`hfgpu.scene_reader.scene_system`)."""
    length = t.quantity("measured_depth", "length", minimum=0.0, exclusive_minimum=True)
    gradient = t.quantity("friction_gradient", "stress_gradient", None, minimum=0.0)
    if gradient is None and not t.has("inner_diameter"):
        raise SceneError(t.key_path("inner_diameter"), MISSING,
                         "this key is required unless [wellbore] friction_gradient is given")
    diameter = t.quantity("inner_diameter", "length", None, minimum=0.0, exclusive_minimum=True)
    if length < perforation_depth:
        raise SceneError(t.key_path("measured_depth"), t.raw("measured_depth"),
                         f"allowed: at least the perforations' true vertical depth ([injection] depth = "
                         f"{display_text(perforation_depth, 'depth', scene_system(), digits=6)})")
    t.finish()
    return Wellbore(measured_depth=length, inner_diameter=diameter, friction_gradient=gradient)


def pipe_friction(wellbore: Wellbore, rate: np.ndarray, density: np.ndarray, viscosity: float) -> np.ndarray:
    """dp_f [Pa] over the measured depth at slurry rates ``rate`` [m^3/s] and densities [kg/m^3] (module
    docstring); 0 where the rate is 0."""
    rate, density = np.asarray(rate, dtype=np.float64), np.asarray(density, dtype=np.float64)
    if wellbore.friction_gradient is not None:
        return np.where(rate > 0.0, wellbore.friction_gradient * wellbore.measured_depth, 0.0)
    d = wellbore.inner_diameter
    speed = rate / (math.pi * d * d / 4.0)
    reynolds = density * speed * d / viscosity
    safe = np.maximum(reynolds, 1e-300)
    fanning = np.where(reynolds < TURBULENT_RE, 16.0 / safe, 0.0791 * safe**-0.25)
    return np.where(rate > 0.0, 2.0 * fanning * density * speed**2 * wellbore.measured_depth / d, 0.0)


def pumped_slurry(scene: Any, time: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(slurry rate [m^3/s], slurry density [kg/m^3]) the schedule pumps at each ``time`` [s] (the stage with
    start < t <= until; clean fluid and rate 0 after the last stage)."""
    time = np.asarray(time, dtype=np.float64)
    densities = scene.proppant.class_densities() if getattr(scene, "proppant", None) is not None else {}
    rate, density = np.zeros(time.shape), np.full(time.shape, scene.fluid.density)
    start = 0.0
    for stage in scene.injection.schedule.stages:
        inside = ((time > start) | (start == 0.0)) & (time <= stage.until)
        share = np.clip((time - start) / max(stage.until - start, 1e-300), 0.0, 1.0)
        phi = stage.volume_fraction + share * (stage.end_volume_fraction - stage.volume_fraction)
        rho_p = densities.get(stage.proppant, scene.fluid.density)
        rate = np.where(inside, stage.rate, rate)
        density = np.where(inside & (stage.rate > 0.0), scene.fluid.density * (1.0 - phi) + rho_p * phi, density)
        start = stage.until
    return rate, density


def surface_pressure(scene: Any, time: np.ndarray, bhtp: np.ndarray) -> np.ndarray:
    """STP [Pa] at ``time`` [s] from the BHTP [Pa] there (module docstring), for a scene with ``[wellbore]``."""
    rate, density = pumped_slurry(scene, time)
    hydrostatic = density * GRAVITY * scene.injection.depth
    return np.asarray(bhtp, dtype=np.float64) - hydrostatic + pipe_friction(scene.wellbore, rate, density,
                                                                            scene.fluid.viscosity)


def surface_pressure_of(scene: Any) -> Callable[[np.ndarray, np.ndarray], np.ndarray] | None:
    """The STP function ``(time [s], BHTP [Pa]) -> STP [Pa]`` of :func:`surface_pressure` for ``scene``, or None
    when it has no ``[wellbore]`` (the results writer stores STP per fracture balance row with it)."""
    return partial(surface_pressure, scene) if getattr(scene, "wellbore", None) is not None else None
