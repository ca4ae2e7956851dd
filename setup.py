"""The one thing pyproject.toml cannot say plainly: the C extension lipclock._kernels.

Its loops (Klatt synthesis, mouth springs, bigram curves) were numba-compiled; a small
C module does the same work without numba's and LLVM's ~120 MB resident at idle.
No -ffast-math and no fused multiply-add, so output is the same on every machine.
"""

from setuptools import Extension, setup

CSRC = "server/lipclock/csrc"

setup(ext_modules=[Extension(
    "lipclock._kernels",
    sources=[f"{CSRC}/module.c", f"{CSRC}/klatt.c", f"{CSRC}/face.c"],
    depends=[f"{CSRC}/kernels.h"],
    extra_compile_args=["-O3", "-ffp-contract=off", "-fno-math-errno", "-std=gnu11"],
)])
