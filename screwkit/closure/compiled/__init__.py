"""The compiled (numba) kernels of closure solving."""
