"""The core: what both papers share (config, rotations, compiled kernels, tables, figures,
verdicts, the workflow glue); it imports nothing of the papers, the report or the edge.

Its kernel modules (:func:`opnav.core.compiled.register_kernel_modules`): every package's
kernels may call them.
"""
from opnav.core.compiled import register_kernel_modules as _register_kernel_modules

_register_kernel_modules(__name__, ("opnav.core.rotations",))
