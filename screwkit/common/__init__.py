"""Shared by every layer: tolerances, units, rotations, input validation, chunked threads, names imported on first
use, and the plumbing of compiled kernels (numba's cache and compile notices).
"""
