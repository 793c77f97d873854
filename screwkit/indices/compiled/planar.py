"""Compiled kernel of the paper's planar closed forms (:func:`screwkit.indices.closed_forms.planar_indices`).

Kept apart from :mod:`screwkit.indices.compiled.algebra` so that the closed-form path loads only this small
function (numba, cached on disk) and not the generic transmission kernel.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit


@njit(nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def planar_closed_form_kernel(base, elbows, distal, directions, triples, threshold, rank_tolerance, iti_out, oti_out,
                              independent_out):
    """The paper's planar closed forms for a chunk of configurations (Eqs. 18-19, 23, 34, A2-A4).

    base, elbows, distal : (N, k, 2) points b_i, c_i, d_i; ``elbows`` may be empty (0, k, 2)
        when ``directions`` (N, k, 2) give the leg directions of RPR chains (ITI = 1).
    triples : (S, 3) chains of each 3-chain submechanism.
    rank_tolerance : the wrenches of a submechanism are dependent when the numerator of A2 (its
        wrench determinant), in units of the characteristic length L of the configuration (the RMS
        distance of the platform joints from their centroid c), is at or below this times the
        product of the norms of its rows ``(f_i, (d_i - c) x f_i / L)``.
    Outputs: iti_out (N, k), oti_out (N, S) = min over the three chains of OTI_k (A4),
        independent_out (N, S): whether each submechanism's wrenches are independent.
    """
    count, chains = distal.shape[0], distal.shape[1]
    rrr = elbows.shape[0] > 0
    f = np.empty((chains, 2))
    fd = np.empty(chains)
    row_norm = np.empty(chains)
    for index in range(count):
        cx = 0.0
        cy = 0.0
        for i in range(chains):
            cx += distal[index, i, 0]
            cy += distal[index, i, 1]
        cx /= chains
        cy /= chains
        spread = 0.0
        for i in range(chains):
            spread += (distal[index, i, 0] - cx) ** 2 + (distal[index, i, 1] - cy) ** 2
        length = np.sqrt(spread / chains)
        if length <= 0.0:
            length = 1.0
        for i in range(chains):
            if rrr:
                fx = distal[index, i, 0] - elbows[index, i, 0]
                fy = distal[index, i, 1] - elbows[index, i, 1]
                gx = elbows[index, i, 0] - base[index, i, 0]
                gy = elbows[index, i, 1] - base[index, i, 1]
                fn = np.sqrt(fx * fx + fy * fy)
                gn = np.sqrt(gx * gx + gy * gy)
                fx /= fn
                fy /= fn
                iti_out[index, i] = abs(gx * fy - gy * fx) / gn  # Eq. 23: |det[g f]|
            else:
                fx = directions[index, i, 0]
                fy = directions[index, i, 1]
                iti_out[index, i] = 1.0
            f[i, 0] = fx
            f[i, 1] = fy
            fd[i] = fx * distal[index, i, 1] - fy * distal[index, i, 0]  # |f_i d_i|
            moment = (fx * (distal[index, i, 1] - cy) - fy * (distal[index, i, 0] - cx)) / length
            row_norm[i] = np.sqrt(fx * fx + fy * fy + moment * moment)
        for s in range(triples.shape[0]):
            k, l, m = triples[s, 0], triples[s, 1], triples[s, 2]
            cross_lm = f[l, 0] * f[m, 1] - f[l, 1] * f[m, 0]
            cross_mk = f[m, 0] * f[k, 1] - f[m, 1] * f[k, 0]
            cross_kl = f[k, 0] * f[l, 1] - f[k, 1] * f[l, 0]
            numerator = abs(fd[k] * cross_lm + fd[l] * cross_mk + fd[m] * cross_kl)  # A2 / A3
            independent_out[index, s] = numerator > rank_tolerance * length * row_norm[k] * row_norm[l] * row_norm[m]
            best = 1.0
            for which in range(3):
                if which == 0:
                    own, first, second, cross = k, l, m, cross_lm
                elif which == 1:
                    own, first, second, cross = l, m, k, cross_mk
                else:
                    own, first, second, cross = m, k, l, cross_kl
                # A4 denominator: || |f_l f_m| d_k - (f_m |f_l d_l| - f_l |f_m d_m|) || = |f_l f_m| rho_kmax
                vx = cross * distal[index, own, 0] - (f[second, 0] * fd[first] - f[first, 0] * fd[second])
                vy = cross * distal[index, own, 1] - (f[second, 1] * fd[first] - f[first, 1] * fd[second])
                denominator = np.sqrt(vx * vx + vy * vy)
                if denominator <= threshold * abs(cross) or denominator <= 0.0:
                    value = 0.0
                else:
                    value = min(numerator / denominator, 1.0)
                best = min(best, value)
            oti_out[index, s] = best
