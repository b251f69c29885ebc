"""The Taichi architectures hfgpu's kernels run on: "cpu" and "cuda", the backends with float64 (Taichi's
Vulkan, Metal and OpenGL lack it). Plain Python, so that a scene's ``arch`` is checked without starting Taichi
(hfgpu.proppant.config); :func:`hfgpu.kernels.runtime.init` refuses the others."""

ARCHES = ("cpu", "cuda")
