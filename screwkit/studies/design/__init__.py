"""Design search: the paper's permutation selection, design families, region metrics and the optimiser."""
