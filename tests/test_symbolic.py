"""Symbolic proofs (sympy) that the generic derivation gives the paper's closed forms.

The generic derivation is re-done here with exact symbols, step by step as
:func:`screwkit.indices.analysis.analyze` does it: joint twists -> actuation wrench from the
reciprocity conditions in the motion space (twists about the platform joint point) ->
wrench matrix in motion coordinates -> adjugate columns as output twists -> power
coefficient. Each identity is then checked as a polynomial identity (difference expands
to zero), so it holds for every configuration, not just sampled ones.
"""

from __future__ import annotations

import sympy as sp

Z = sp.Matrix([0, 0, 1])
# Orthonormal basis of the planar motion space (omega_z, v_x, v_y) as twists (omega, v).
BASIS = [sp.Matrix([0, 0, 1, 0, 0, 0]), sp.Matrix([0, 0, 0, 1, 0, 0]), sp.Matrix([0, 0, 0, 0, 1, 0])]


def point(name):
    x, y = sp.symbols(f"{name}_x {name}_y", real=True)
    return sp.Matrix([x, y, 0])


def revolute_z(p):
    return sp.Matrix.vstack(Z, p.cross(Z))


def shift(twist, p):
    """Twist about p: (omega, v + omega x p)."""
    omega, velocity = twist[:3, :], twist[3:, :]
    return sp.Matrix.vstack(omega, velocity + omega.cross(p))


def swap(screw):
    return sp.Matrix.vstack(screw[3:, :], screw[:3, :])


def reciprocal(first, second):
    return (first[:3, :].T * second[3:, :] + first[3:, :].T * second[:3, :])[0, 0]


def actuation_wrench(b, c, d):
    """Generic actuation wrench of an RRR chain with its base joint actuated (world frame)."""
    joints = [shift(revolute_z(p), d) for p in (b, c, d)]
    shifted_basis = [shift(m, d) for m in BASIS]
    rows = [[(joint.T * m)[0, 0] for m in shifted_basis] for joint in joints[1:]]  # passive joints
    x = sp.Matrix(rows[0]).cross(sp.Matrix(rows[1]))
    wrench_about_d = swap(sum((x[q] * shifted_basis[q] for q in range(3)), sp.zeros(6, 1)))
    force = wrench_about_d[:3, :]
    return sp.Matrix.vstack(force, wrench_about_d[3:, :] + d.cross(force))


def is_zero(expression):
    return sp.expand(expression) == 0


def det2(u, v):
    return u[0] * v[1] - u[1] * v[0]


def test_actuation_wrench_is_the_force_along_the_distal_link():
    """Eq. (21): the generic wrench is a force along d - c through d (zero pitch, no z part)."""
    b, c, d = point("b"), point("c"), point("d")
    wrench = actuation_wrench(b, c, d)
    force, moment = wrench[:3, :], wrench[3:, :]
    assert is_zero(force[2])
    assert is_zero(det2(force, d - c))  # parallel to the distal link
    assert all(is_zero(e) for e in (moment - d.cross(force)))  # its axis passes through d
    assert not is_zero(force[0]) or not is_zero(force[1])


def test_iti_is_the_sine_of_the_elbow_angle():
    """Eq. (23): ITI_i = |det[g_i f_i]|, from the generic power coefficient at c_i."""
    b, c, d = point("b"), point("c"), point("d")
    wrench = actuation_wrench(b, c, d)
    input_twist = revolute_z(b)
    numerator = reciprocal(wrench, input_twist)
    # |A o T|_max = |f| |v + omega x p| with p = c (on the wrench axis, zero pitch).
    arm = input_twist[3:, :] + input_twist[:3, :].cross(c)
    force = wrench[:3, :]
    g, f = c - b, d - c
    # PC^2 = num^2 / (|f_w|^2 |arm|^2) must equal det[g f]^2 / (|g|^2 |f|^2).
    left = numerator**2 * (f.dot(f)) * (g.dot(g))
    right = det2(g, f) ** 2 * force.dot(force) * arm.dot(arm)
    assert is_zero(left - right)


def _submechanism():
    """Three chains whose wrenches have the form proven generic above: (f, d x f), f free."""
    points = [(None, None, point(f"d{i}")) for i in range(3)]
    forces = [sp.Matrix([*sp.symbols(f"f{i}_x f{i}_y", real=True), 0]) for i in range(3)]
    wrenches = [sp.Matrix.vstack(f, chain[2].cross(f)) for f, chain in zip(forces, points)]
    matrix = sp.Matrix([[reciprocal(w, m) for m in BASIS] for w in wrenches])
    return points, wrenches, matrix, matrix.adjugate()


def test_oti_equals_a4():
    """Eq. (A4) (with the cyclic numerator of A2) equals the generic OTI_k for every chain k."""
    points, wrenches, matrix, adjugate = _submechanism()
    det = matrix.det()
    forces = [w[:3, :] for w in wrenches]
    ds = [chain[2] for chain in points]
    for k, l, m in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        twist = sum((adjugate[q, k] * BASIS[q] for q in range(3)), sp.zeros(6, 1))
        assert is_zero(reciprocal(wrenches[k], twist) - det)  # A_k o T_k = det W (general form of A3)
        arm = twist[3:, :] + twist[:3, :].cross(ds[k])
        f_k, f_l, f_m = forces[k], forces[l], forces[m]
        numerator = (det2(f_k, ds[k]) * det2(f_l, f_m) + det2(f_l, ds[l]) * det2(f_m, f_k)
                     + det2(f_m, ds[m]) * det2(f_k, f_l))
        vector = det2(f_l, f_m) * ds[k][:2, :] - (f_m[:2, :] * det2(f_l, ds[l]) - f_l[:2, :] * det2(f_m, ds[m]))
        # (|det W| / |arm|)^2 == (numerator / |vector|)^2
        assert is_zero(det**2 * vector.dot(vector) - numerator**2 * arm.dot(arm))


def test_a3_shared_numerator():
    """Eq. (A3): |A_k o O_k| |f_l f_m| is the same for k, l, m with O_k a unit rotation twist."""
    points, wrenches, matrix, adjugate = _submechanism()
    forces = [w[:3, :] for w in wrenches]
    # O_k = adj column k / omega_z; A_k o O_k = det W / adj[0, k]. Compare the squares crosswise.
    values = []
    for k, l, m in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        values.append((det2(forces[l], forces[m]), adjugate[0, k]))
    (n0, w0), (n1, w1), (n2, w2) = values
    assert is_zero((n0 * w1) ** 2 - (n1 * w0) ** 2)
    assert is_zero((n0 * w2) ** 2 - (n2 * w0) ** 2)


def test_literal_a4_extraction_differs():
    """The extracted (A4) shows |f_l d_k| in its second term: that reading is not the OTI."""
    f = [sp.Matrix([1, 0]), sp.Matrix([0, 1]), sp.Matrix([1, 1]) / sp.sqrt(2)]
    d = [sp.Matrix([0, 0]), sp.Matrix([1, 0]), sp.Matrix([0, 1])]
    cyclic = (det2(f[0], d[0]) * det2(f[1], f[2]) + det2(f[1], d[1]) * det2(f[2], f[0])
              + det2(f[2], d[2]) * det2(f[0], f[1]))
    literal = (det2(f[0], d[0]) * det2(f[1], f[2]) + det2(f[1], d[0]) * det2(f[2], f[0])
               + det2(f[2], d[2]) * det2(f[0], f[1]))
    assert sp.simplify(cyclic - literal) != 0
