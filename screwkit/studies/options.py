"""What a study computes at every pose, as one record passed from the command line to the tasks.

:class:`AnalysisOptions` holds the settings of :func:`screwkit.studies.indices_at_poses` that a sweep, a
map or a design region passes on unchanged (the singularity threshold, the numbers of faults, the fault
type, the planar closed forms, the joint limits); where the work runs is a
:class:`screwkit.studies.tasks.Execution`.
"""

from __future__ import annotations

from contextlib import nullcontext
from dataclasses import asdict, dataclass

import numpy as np

from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.indices.average import AGGREGATES, averaging
from screwkit.indices.faults import FAULT_TYPES

__all__ = ["AnalysisOptions", "checked_analysis"]


@dataclass(frozen=True)
class AnalysisOptions:
    """The indices asked for at every pose of a study.

    Attributes
    ----------
    threshold : float
        Singularity threshold *p* on the moment arm (m).
    faults : tuple of int, optional
        The numbers of faults ``j`` (default all); an int or any sequence is kept as a tuple.
    fault_type : {"free-swinging", "link"}
        What a failed actuator does (see :func:`screwkit.indices.analysis.analyze`).
    closed_forms : bool
        The paper's planar closed forms instead of the generic screw path.
    limits : bool
        Whether a pose that puts a joint outside its position limits is unreachable.
    aggregate : {"min", "mean"}
        ``"mean"`` adds the average case of Eq. 12 beside the worst case: ``f_o_mean{j}``, the (weighted) mean over
        the sets of ``j`` failures of the LMTI left (:mod:`screwkit.indices.average`, screwkit's extension).
    probabilities : tuple of float, optional
        Each actuator's failure probability, weighting the mean (with ``aggregate="mean"``).
    """

    threshold: float = SINGULARITY_THRESHOLD
    faults: tuple[int, ...] | None = None
    fault_type: str = "free-swinging"
    closed_forms: bool = False
    limits: bool = True
    aggregate: str = "min"
    probabilities: tuple[float, ...] | None = None

    def __post_init__(self):
        if self.fault_type not in FAULT_TYPES:
            raise ValueError(f"Expected `fault_type` in {', '.join(FAULT_TYPES)}, got {self.fault_type!r}.")
        if self.faults is not None:
            object.__setattr__(self, "faults", tuple(int(j) for j in np.atleast_1d(self.faults).tolist()))
        if self.aggregate not in AGGREGATES:
            raise ValueError(f"Expected `aggregate` in {', '.join(AGGREGATES)}, got {self.aggregate!r}.")
        if self.probabilities is not None:
            if self.aggregate != "mean":
                raise ValueError("Failure probabilities weight the mean: give them with aggregate='mean'.")
            object.__setattr__(self, "probabilities", tuple(float(p) for p in np.atleast_1d(self.probabilities)))

    def keywords(self) -> dict:
        """The same settings as the keywords of :func:`screwkit.studies.indices_at_poses` (the aggregate is
        registered, :meth:`indices`)."""
        keywords = asdict(self)
        del keywords["aggregate"], keywords["probabilities"]
        return keywords

    def indices(self):
        """A context in which the indices asked for are registered: with ``aggregate="mean"``, the average case
        (:func:`screwkit.indices.average.averaging`); else nothing to do."""
        return averaging(self.probabilities) if self.aggregate == "mean" else nullcontext()


def checked_analysis(analysis, function: str) -> AnalysisOptions:
    """``analysis`` (None: the default :class:`AnalysisOptions`), or a TypeError saying what ``function`` takes."""
    if analysis is None:
        return AnalysisOptions()
    if not isinstance(analysis, AnalysisOptions):
        hint = f": pass AnalysisOptions(**{analysis!r:.60})" if isinstance(analysis, dict) else ""
        raise TypeError(f"{function} expects `analysis` as a screwkit.studies.options.AnalysisOptions, got "
                        f"{type(analysis).__name__}{hint}.")
    return analysis
