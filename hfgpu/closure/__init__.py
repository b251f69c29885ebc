"""Closure of the fracture on its proppant: propped width, pack permeability and conductivity (docs/closure.md).

Modules: :mod:`.config` (the scene's ``[closure]`` section and the per-class keys of ``[[proppant]]``),
:mod:`.pack` (settling rule and propped width), :mod:`.permeability` (Kozeny-Carman and vendor tables),
:mod:`.conductivity` (the map and its scalars, from a results file).
"""
