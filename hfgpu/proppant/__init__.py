"""Pseudo-3D MP-PIC proppant transport (the paper, sections 2.3, 3.2, 4.2)."""
