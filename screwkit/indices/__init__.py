"""The paper's indices: the analysis (`analyze`), the actuator sets and their reductions, link faults, the
paper's closed forms, the one result type and its exports.
"""
