"""Planar-3D hydraulic fracture propagation (the paper, sections 2.2, 3.1, 4.1)."""
