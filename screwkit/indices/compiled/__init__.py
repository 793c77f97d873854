"""The compiled (numba) kernels of the index pipeline; each has a plain-numpy counterpart in
:mod:`screwkit.screw.reference`.
"""
