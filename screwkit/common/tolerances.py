"""Every numerical tolerance of screwkit, named once, with its unit and meaning.

Lengths are metres; "relative" tolerances are dimensionless. The math core compares
dimensionless quantities only (screws are expressed about the centroid of the platform
joints with lengths in units of a characteristic length of the configuration, see
:mod:`screwkit.indices.analysis`), so that every decision it takes is independent of the length
unit, the scale of the mechanism and the world frame. The one tolerance with a unit that
enters the indices is the paper's singularity threshold *p*.
Only the standard library is imported here.
"""

from __future__ import annotations

# -- indices (math core) ----------------------------------------------------------------
# Every tolerance below but SINGULARITY_THRESHOLD is dimensionless and is applied in working
# coordinates: screws about the centroid c of the platform joints, lengths divided by
# L = sqrt(mean_j |p_j - c|^2) over every joint point p_j of the configuration, so that a twist
# (omega, v) becomes (omega, v_c / L) and a wrench (f, m) becomes (f, m_c / L). The compiled
# kernel receives them as arguments (numba's disk cache would not see a changed constant).

SINGULARITY_THRESHOLD = 1e-6
"""The paper's singularity threshold *p* (m, the unit of the screws): a power coefficient is zero
when the moment arm of its wrench about its characteristic point is at or below *p* (Sec. 4,
1 um). The only length among the tolerances: it is compared as ``arm / L <= p / L``, so it must
be scaled with the mechanism (a mechanism in millimetres needs ``p = 1e-3``)."""

RANK_TOLERANCE = 1e-9
"""Relative: the actuation wrenches of a non-redundant submechanism are dependent (its OTI is
zero) when ``|det W|`` is at or below this times the product of the norms of the rows of ``W``
(``W = [A_k o M_q]`` with an orthonormal basis ``M`` of the motion space, working coordinates)."""

MOTION_SPACE_TOLERANCE = 1e-9
"""Relative: a chain's joint twists, each scaled to unit norm in working coordinates, are
dependent when a singular value of their matrix is at or below this times the largest."""

MOTION_SPACE_EIGENVALUE = 1e-8
"""Dimensionless: a twist belongs to the platform's motion space when ``sum_i (I - P_i)``
(``P_i`` the orthogonal projector on chain i's twist space, working coordinates) has an
eigenvalue at or below this along it (each ``I - P_i`` has eigenvalues 0 and 1)."""

EIGENVALUE_RESOLUTION = 1e-10
"""Dimensionless: where the eigenvalue of ``sum_i (I - P_i)`` just past the motion space's ``n`` is at or below this,
numpy's eigenvectors do not tell the motion space from the twists next to it (its eigen-solver resolves eigenvalues to
about 1e-16 of the matrix's norm, so the chains' complements' singular values only to about 1e-8): the ``n`` least
singular directions of the stacked complements are taken instead, as well as the chains' twists determine them (about
1e-16 over the gap: 1e-7 for legs' couples 1e-9 from parallel, which :data:`MOTION_SPACE_TOLERANCE` counts as
independent; :func:`screwkit.screw.motion.motion_bases`). The compiled kernel's Jacobi eigen-solver resolves small
eigenvalues to their own precision and needs no such step."""

CONSTANT_BASIS_TOLERANCE = 1e-8
"""Dimensionless: orthonormal motion-space bases (working coordinates) found at sample
configurations span the same space when one differs from its projection on the other by at
most this, entry by entry."""

OUTSIDE_CONSTANT_SPACE = 1e-9
"""Relative: a joint twist leaves a constant motion space when the norm of its component
outside the space is larger than this times its norm (working coordinates); the configuration
then gets its own motion space."""

REPEATED_PAIRING = 1e-6
"""Relative: singular values of a chain's pairing of released constraint wrenches with the twists their release frees
(orthonormal bases, working coordinates) that differ by at most this times the largest are one repeated value. Its
singular vectors are then any rotation of each other within their block, and the CTI takes the block's worst
rotation (:func:`screwkit.screw.principal_pairs.worst_in_blocks`). A convention at its edge: values that differ by
a little more are paired by their singular vectors, which the block's worst rotation need not be the limit of."""

PURE_COUPLE = 1e-10
"""Relative: a wrench is a pure couple (infinite pitch) when ``|f| * L`` is at or below this
times ``|m|`` (the moment about the centroid; :func:`screwkit.screw.algebra.power_coefficient` takes
it about the characteristic point with its ``length`` argument as ``L``)."""

AXIS_PARALLEL = 1e-12
"""Relative: a joint's axis is parallel to a wrench's axis when the squared sine of the angle between them is at
or below this; the characteristic point on the wrench axis (the point nearest to the joint's axis) is then the
projection of the joint's point instead (:func:`screwkit.screw.algebra.nearest_on_axis`)."""

ZERO_PITCH = 1e-9
"""Relative: a wrench is a force (zero pitch) when its pitch is at most this times the characteristic length ``L``
(working coordinates). Only a force is sure to cross the axis of a revolute it is reciprocal to; the characteristic
point of a wrench with a pitch (a serial arm's) is the joint's drawn point projected on its axis
(:func:`screwkit.screw.algebra.nearest_on_axis`)."""

SAME_POINT = 1e-5
"""Relative: two neighbouring joints of a chain are drawn at the same point when their points are at most this
apart (working coordinates); with axes that are not parallel they are a universal or a ball joint, whose
characteristic point is that point, not a line (:func:`screwkit.screw.algebra.joint_lines`). As loose as
:data:`MEETING`: the revolutes of a ball whose axes a file rounds so that they miss by a little meet, and their
canonical points (each on its own axis) are then that little apart; read as three lines, a force along one of
them would cross it wherever the rounding puts the crossing (an ITI of 0.978 for 0.858 on a published Stewart
head drawn another way)."""

MEETING = 1e-5
"""Relative to a chain's extent (its lines' own, :func:`screwkit.closure.canonical.chain_extent`): two neighbouring
revolutes of a chain whose axes are not parallel and pass at most this far apart meet, a universal or ball joint
(:mod:`screwkit.closure.canonical`); loose enough for a file whose lengths are rounded to six decimals."""

PARALLEL_FOOT = 1e-2
"""Squared sine: two neighbouring revolute axes of a chain are too near parallel (within 5.7 degrees) for the foot of
their common perpendicular to place a joint (it would lie up to ten times their offset away, and at infinity for
parallel axes); the joint's canonical point then comes along the run of parallel axes
(:mod:`screwkit.closure.canonical`). A constant of a design: consecutive joints share a link."""

MEETING_TIE = 1e-4
"""Squared sine: an axis that meets both its neighbours' at two points (:data:`MEETING`) through which as many of the
chain's axes pass meets them at equally clear angles when the squared sines of the two angles differ by at most this
(0.6 degrees about a right angle), and takes the mean of the two points; otherwise the meeting more axes pass
through, then the clearer one (:mod:`screwkit.closure.canonical`). Loose enough for axes written to six decimals."""

GRAM_PIVOT = 1e-12
"""Relative: the Gram matrix of a chain's joint twists (about the platform joint, each scaled to
unit norm in working coordinates, so its diagonal is 1) is singular (an idle DoF, e.g. the spin
of an S-S rod) when a pivot of its elimination is at or below this times its largest diagonal
entry."""

SINGULAR_SPAN = 1e-6
"""Relative: at an input singularity (a chain whose Gram matrix, above, is singular and has no consistent
solution), the actuation wrench is sought in the span of the chain's unit twists and the motion space; a direction
whose remainder is at most this does not count. It is the square root of GRAM_PIVOT: the twists' own singular
values below it are the ones the Gram elimination called singular (a leg stretched to within rounding has one of
about 1e-8, the square root of rounding)."""

PSEUDO_INVERSE_CONSISTENCY = 1e-9
"""Relative: a pseudo-inverse solution of a singular Gram system (above) is kept when its
largest residual is at most this times ``max(1, largest entry of the solution)``; otherwise the
actuation wrench is zero (the actuated joint's twist depends on the chain's other twists)."""

WORST_FAULT_TIE = 1e-12
"""Dimensionless, absolute (indices lie in [0, 1]): the worst fault set reported with ``F_Oj`` is
the first set, in combination order, whose LMTI is at most ``F_Oj`` plus this. Rounding can
reorder sets whose LMTIs are mathematically equal; their differences are absolute, of order
1e-16, also where the index is small, hence an absolute margin rather than one relative to the
minimum."""

# -- closure and model ------------------------------------------------------------------

CLOSURE_TOLERANCE = 1e-6
"""Metres and radians: the largest loop gap accepted at the reference configuration of a
file, and the tolerance of recognising a chain's closed-form type (axes parallel, points
coincident, axes along z), so that a file written to 6 decimals keeps its closed forms."""

BOUNDARY_ROUNDING = 1e-12
"""Dimensionless: how far a closed-form chain's end may lie beyond the boundary of its reach (relative to the
squared distances of the R-R-R leg's or the R-U-S leg's equation) and still be reached, stretched or folded: there
the sign that decides is set by rounding, which the unit and the world frame of the file change (a pose of a map at
the boundary was reachable in metres and not in millimetres)."""

FILE_ROUNDING = 1e-5
"""Relative (lengths in units of the mechanism's length scale, radians): how far a file of another tool may miss the
mechanism its author drew because its numbers are written rounded (CAD exporters and Gazebo write 6 decimals: a
micrometre on links of decimetres, a microradian on an axis). Redundant closures that its rounding leaves apart
by at most this are closed as well as they can be (:mod:`screwkit.io.closed_tree`); an overconstrained loop that its
rounding makes rigid (a parallelogram of hinges whose axes are parallel to 6 decimals) moves as drawn when the
singular value of its closure Jacobian that locks it is at most this (:mod:`screwkit.io.compound`). It is used where
a file is read, once, never on the configurations of a study."""

ROUNDED_COUPLE = 1e-3
"""Relative (working coordinates): a constraint wrench whose force is at most this times its moment about the
centroid (its line passes farther than 1000 working lengths from the mechanism, where an actuation wrench already acts
as a couple: ``screwkit.io.graph_checks.COUPLE_LIKE``) is scored in the CTI as the couple it nearly is. Two rods a file
writes rounded off parallel hold a force through where their lines meet, far away, and scored as a force there its
power coefficient did not tend to the couple's (a CAD Delta's CTI read 0.99704 for its parallelograms' 0.99588).
Written to 6 decimals in metres, a rod Delta's rods of 55 cm give 1.4e-5 of force per moment, of 5.5 cm 7.8e-5, of
1.1 cm 5.5e-4; to 4 decimals, rods of 55 cm up to 1.25e-3. ``docs/theory.md``, *Not settled either*."""

NEWTON_TOLERANCE = 1e-11
"""Radians and length scales: a chain solved by damped Newton is closed when its loop error norm
(rotation in rad, translation divided by the mechanism's length scale) is below this."""

IN_LOOP_RATE = 1e-6
"""The actuated joint's rate in the unit null vectors of its leg's closure rows, its path's other joints held, above
which it moves (:func:`screwkit.io.graph_screws.drives_rigidly`; joint rates in working coordinates: the verdict does
not turn on the unit)."""

LIMIT_SLACK = 1e-9
"""Radians, and length scales: how far beyond a position limit (relative to 1 rad or length scale plus the limit's
size) a joint may be and still be at it (:func:`screwkit.closure.solve.slackened`: the same for a mechanism and any
scaled copy). Joint values come from closures solved to :data:`NEWTON_TOLERANCE` and from poses asked in rounded
numbers: a crank drawn at its stop, asked at the home pose as printed (7.7e-13 m from it), was put 3.8e-11 rad past
the stop and the pose refused. The serial and the graph readings take the same slack."""

BRANCH_MATCH_TOLERANCE = 1e-4
"""Radians, and metres relative to the mechanism's length scale: the closed-form branch closest
to the reference assembly is its working mode when every joint value matches it to this. Working
modes lie far apart; the reference values of a file whose loops close only to
:data:`CLOSURE_TOLERANCE` differ from an exact closure by a few times that."""
