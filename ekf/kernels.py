"""Compiled kernels shared by the paper EKF (:mod:`ekf.filter`), the raw-log EKF
(:mod:`ekf.log_filter`) and the Fisher information (:mod:`trials.planning.fisher`).

The filters differ only in which :mod:`mmg.model` state slots they propagate and where the
estimated hull derivatives sit in their state z:

* paper filter: z = [u, v, r, n, c_1 .. c_12], slots ``[U_, V_, R_, N_]``, derivatives from z[4];
* raw-log filter: z = [x, y, psi, n, u, v, r, tau, c_1 .. c_12], slots
  ``[X_, Y_, PSI_, N_, U_, V_, R_]``, derivatives from z[8] (tau, the rudder-timing offset, is
  held like the derivatives and enters through the rudder angle, see :func:`jacobian_step`).

So one RK4 step (:func:`rk4_step`, the step :func:`mmg.rk4.rk4_step` of every integrator), one
exact Jacobian of it (:func:`jacobian_step`: the tangent-linear RK4, state columns by complex step
of each stage, derivative columns analytic), one covariance propagation (:func:`fpft`) and one measurement update (:func:`joseph_update_ws`) serve
both; the only physics is :func:`mmg.model` (:func:`~mmg.model.rhs` and the parts it is made of).
:func:`jacobian_step_reference` keeps the brute-force complex step (one complex RK4 step per
column of F, ~5 x slower for the paper filter) as the reference for tests and ``bench/bench_ekf.py``.
"""
from __future__ import annotations

import numpy as np
from mmg._jit import njit
from mmg.kernel import axpy8
from mmg.model import DELTA_, N_, P_WIND_V, PSI_, R_, U_, V_, X_, Y_, dynamics, inverse_mass, rhs_hull_jacobian, rhs_of, track
from mmg.rk4 import NODES, WEIGHTS
from mmg.rk4 import rk4_step as rk4

CSTEP = 1e-30               # complex-step size: F = Im(step(z + i h e_j)) / h, exact to rounding


@njit(cache=True, error_model="numpy", inline="always")
def _at(z, slots, j, zero):
    """z[i] where slots[i] == j (the mmg state j as the filter holds it), else ``zero``."""
    for i in range(slots.shape[0]):
        if slots[i] == j:
            return z[i] + zero
    return zero


@njit(cache=True, error_model="numpy", inline="always")
def _filter_rhs(y, tau, args):
    """The filters' right-hand side for :func:`mmg.rk4.rk4_step`: :func:`mmg.model.rhs_of` at the stage
    state ``y`` (an 8-tuple of mmg states) with the rudder d0 (tau 0), its mean (1/2) or d1 (1), the
    derivatives of the states the filter does not propagate (bit j of ``mask`` clear) held at 0."""
    d0, d1, mask, p, poly, hull_axis, hull_term, coef = args
    d = d0 if tau == 0.0 else (d1 if tau == 1.0 else 0.5 * (d0 + d1))
    k = rhs_of(y[U_], y[V_], y[R_], y[PSI_], d, y[N_], d.real, p, poly, hull_axis, hull_term, coef)
    z = 0j
    return (k[0] if mask & 1 else z, k[1] if (mask >> 1) & 1 else z, k[2] if (mask >> 2) & 1 else z,
            k[3] if (mask >> 3) & 1 else z, k[4] if (mask >> 4) & 1 else z, k[5] if (mask >> 5) & 1 else z,
            k[6] if (mask >> 6) & 1 else z, k[7] if (mask >> 7) & 1 else z)


@njit(cache=True)
def rk4_step(z, d0, d1, dt, layout, ship, ws):
    """One RK4 step (:func:`mmg.rk4.rk4_step`) of the dynamic states of z over ``dt`` [s]; real or complex z.

    z[i] (i < len(slots)) is the mmg state ``slots[i]`` (SI units: m/s, rad/s, m, rad, rps);
    z[c0 + j] is the hull derivative written into ``coef[idx[j]]`` (``coef`` a complex copy of
    the packed ship's ``hull_coef``), held over the step; other mmg states are 0.
    d0, d1: rudder angle [rad] at the start and end of the step (real, or complex to carry a
    complex-step perturbation), linear over the step: it enters as the DELTA_ state (d0 for
    stage 1, the mid value for stages 2-3, d1 for stage 4) and its real part as the command.
    layout = (slots, c0, idx, itau) (itau not used: the rudder d0, d1 comes whole), ship = (p, poly,
    hull_axis, hull_term); ws from :func:`make_workspace`: its complex work arrays coef = ws[1]
    and out = ws[7]: out[:len(slots)] <- z_next of the dynamic states.
    """
    slots, c0, idx, _ = layout
    p, poly, hull_axis, hull_term = ship
    coef, out = ws[1], ws[7]
    for j in range(idx.shape[0]):
        coef[idx[j]] = z[c0 + j]
    zero = 0j
    mask = 0
    for i in range(slots.shape[0]):
        mask |= 1 << slots[i]
    y = (_at(z, slots, 0, zero), _at(z, slots, 1, zero), _at(z, slots, 2, zero), _at(z, slots, 3, zero),
         _at(z, slots, 4, zero), _at(z, slots, 5, zero), _at(z, slots, 6, zero), _at(z, slots, 7, zero))
    zeros = (zero, zero, zero, zero, zero, zero, zero, zero)
    y = rk4(_filter_rhs, axpy8, zeros, y, dt, (d0, d1, mask, p, poly, hull_axis, hull_term, coef))
    for i in range(slots.shape[0]):
        out[i] = y[slots[i]]


@njit(cache=True)
def make_workspace(nz, ns, hull_coef):
    """Work arrays of :func:`jacobian_step` (and :func:`jacobian_step_reference`) for nz states of
    which ns are propagated: (zc, coef, -, -, -, -, -, out, z_next, F, hc, xr, kc, kr, ks, A, dK,
    dKn, B, w); coef a complex and hc a real copy of ``hull_coef``.  zc, coef and out are the complex
    work arrays of :func:`rk4_step` and :func:`jacobian_step_reference`, z_next = ws[8], F = ws[9];
    ws[10:] those of the tangent-linear RK4; ws[2:7] are empty (the filters' step keeps its stages in
    registers, :func:`mmg.rk4.rk4_step`)."""
    coef = np.empty(hull_coef.shape[0], dtype=np.complex128)
    for i in range(hull_coef.shape[0]):
        coef[i] = hull_coef[i]
    none = np.empty(0, dtype=np.complex128)
    return (np.empty(nz, dtype=np.complex128), coef, none, none, none, none, none, np.empty(ns, dtype=np.complex128),
            np.empty(nz), np.empty((nz, nz)),
            hull_coef.copy(), np.zeros(8), np.zeros(8, dtype=np.complex128), np.empty(ns), np.empty(ns),
            np.zeros((ns, ns + 1)), np.zeros((ns, nz)), np.zeros((ns, nz)), np.empty((3, max(nz - ns, 0))),
            np.empty(8))


@njit(cache=True)
def _held_rows(z, ns, z_next, F):
    """z_next = z and F = identity on the held states (rows ns..)."""
    nz = z.shape[0]
    for i in range(ns, nz):
        z_next[i] = z[i]
        for j in range(nz):
            F[i, j] = 1.0 if i == j else 0.0


@njit(cache=True, error_model="numpy")
def _dynamics_complex(u, v, r, delta, n, p, poly, hull_axis, hull_term, hull_coef, out):
    """:func:`mmg.model.dynamics` (inlined here), called with all-complex states: compiled once for
    all-complex states and called (not inlined), every column of :func:`jacobian_step` goes through
    this one specialisation, where inlining a copy per column (each with its own mix of real and
    complex arguments) tripled the kernel's compile time."""
    dynamics(u, v, r, delta, n, p, poly, hull_axis, hull_term, hull_coef, out)


@njit(cache=True, error_model="numpy", inline="always")
def _dynamics_column(k, u, v, r, delta, n, p, poly, hull_axis, hull_term, hull_coef, out):
    """:func:`mmg.model.dynamics` with a complex step in state ``k`` (U_, V_, R_, N_ or DELTA_)."""
    h = 1j * CSTEP
    _dynamics_complex(u + (h if k == U_ else 0j), v + (h if k == V_ else 0j), r + (h if k == R_ else 0j),
                      delta + (h if k == DELTA_ else 0j), n + (h if k == N_ else 0j),
                      p, poly, hull_axis, hull_term, hull_coef, out)


@njit(cache=True, error_model="numpy", inline="always")
def _track_column(k, u, v, r, psi, p, out):
    """:func:`mmg.model.track` with a complex step in state ``k`` (U_, V_, R_ or PSI_)."""
    h = 1j * CSTEP
    if k == U_:
        track(u + h, v, r, psi, p, out)
    elif k == V_:
        track(u, v + h, r, psi, p, out)
    elif k == R_:
        track(u, v, r + h, psi, p, out)
    else:
        track(u, v, r, psi + h, p, out)


@njit(cache=True, error_model="numpy", inline="always")
def _take_column(kc, slots, mask, c, have_real, A, kr):
    """From one complex-step evaluation ``kc`` (8,): column c of A on the rows in ``mask`` (bit i: row
    i, state ``slots[i]``), and their real parts into kr unless ``have_real`` (k_s already taken)."""
    for i in range(slots.shape[0]):
        if (mask >> i) & 1:
            A[i, c] = kc[slots[i]].imag / CSTEP
            if not have_real:
                kr[i] = kc[slots[i]].real


@njit(cache=True, error_model="numpy", inline="always")
def _slot_roles(slots):
    """(iu, iv, ir, tmask, dmask) of the propagated slots: the rows of u, v, r (-1 when absent);
    bit i of tmask: row i is a track state (x0, y0, psi), of dmask: a dynamic state (u, v, r, n)."""
    iu = -1
    iv = -1
    ir = -1
    tmask = 0
    dmask = 0
    for i in range(slots.shape[0]):
        sl = slots[i]
        if sl == U_:
            iu = i
        elif sl == V_:
            iv = i
        elif sl == R_:
            ir = i
        if sl == X_ or sl == Y_ or sl == PSI_:
            tmask |= 1 << i
        elif sl == U_ or sl == V_ or sl == R_ or sl == N_:
            dmask |= 1 << i
        else:
            raise ValueError("slots: the rudder angle is an input, not a propagated state")
    return iu, iv, ir, tmask, dmask


@njit(cache=True, error_model="numpy", inline="always")
def _stage(st, dt, e0, e1, g0, g1):
    """(a_s dt, RK4 weight, rudder [rad], its d / d tau [rad/s]) of RK4 stage st (0..3): the node and
    weight of :func:`mmg.rk4.rk4_step` (:data:`mmg.rk4.NODES`, :data:`mmg.rk4.WEIGHTS`); the rudder is
    linear over the step, so at the nodes 0 and 1 its ends and at the middle nodes their mean."""
    tau = NODES[st]
    if tau == 0.0:
        return tau * dt, WEIGHTS[st], e0, g0
    if tau == 1.0:
        return tau * dt, WEIGHTS[st], e1, g1
    return tau * dt, WEIGHTS[st], 0.5 * (e0 + e1), 0.5 * (g0 + g1)


@njit(cache=True, error_model="numpy", inline="always")
def _stage_columns(xr, layout, roles, ship, ws):
    """A_s (column ns: d f / d delta) at the stage state xr by complex step, and k_s (the real parts
    of the first evaluations) into kr = ws[13]; A = ws[15]."""
    slots, _, _, itau = layout
    _, _, _, tmask, dmask = roles
    p, poly, hull_axis, hull_term = ship
    hc, kc, kr, A, w = ws[10], ws[12], ws[13], ws[15], ws[19]
    ns = slots.shape[0]
    u, v, r, psi, n, e = xr[U_], xr[V_], xr[R_], xr[PSI_], xr[N_], xr[DELTA_]
    dyn_real = dmask == 0
    trk_real = tmask == 0
    for c in range(ns + 1):
        if c < ns:
            k = slots[c]
        elif itau >= 0:
            k = DELTA_
        else:
            break
        for i in range(ns):
            A[i, c] = 0.0
        if dmask != 0 and (k == U_ or k == V_ or k == R_ or k == N_ or k == DELTA_):
            _dynamics_column(k, u, v, r, e, n, p, poly, hull_axis, hull_term, hc, kc)
            _take_column(kc, slots, dmask, c, dyn_real, A, kr)
            dyn_real = True
        if tmask != 0 and (k == U_ or k == V_ or k == R_ or k == PSI_):
            _track_column(k, u, v, r, psi, p, kc)
            _take_column(kc, slots, tmask, c, trk_real, A, kr)
            trk_real = True
    if not dyn_real:                # no dynamic state to differentiate in: k_s alone
        dynamics(u, v, r, e, n, p, poly, hull_axis, hull_term, hc, w)
        for i in range(ns):
            if (dmask >> i) & 1:
                kr[i] = w[slots[i]]
    if not trk_real:
        track(u, v, r, psi, p, w)
        for i in range(ns):
            if (tmask >> i) & 1:
                kr[i] = w[slots[i]]


@njit(cache=True, error_model="numpy", inline="always")
def _stage_tangent(first, a, ge, itau, A, dK, dKn):
    """dKn = A_s (E + a dK) + a_delta g_s e_tau (dK = dk_{s-1}, not used at the first stage)."""
    ns, nz = dKn.shape
    for i in range(ns):
        for j in range(nz):
            dKn[i, j] = 0.0
        if not first:
            for c in range(ns):
                aic = a * A[i, c]
                for j in range(nz):
                    dKn[i, j] += aic * dK[c, j]
        for j in range(ns):
            dKn[i, j] += A[i, j]
        if itau >= 0:
            dKn[i, itau] += A[i, ns] * ge


@njit(cache=True, error_model="numpy", inline="always")
def _add_hull_columns(B, roles, c0, m, dK):
    """dK[u, v, r rows, c0 + j] += B_s[:, j], j < m (the analytic d f / d c)."""
    iu, iv, ir, _, _ = roles
    for j in range(m):
        if iu >= 0:
            dK[iu, c0 + j] += B[0, j]
        if iv >= 0:
            dK[iv, c0 + j] += B[1, j]
        if ir >= 0:
            dK[ir, c0 + j] += B[2, j]


# _nrt=False: no reference counting in this kernel (it allocates nothing; the work arrays live in
# ws).  The inlined model code otherwise increfs / decrefs every array argument at every inlined
# call, ~20 % of this kernel's time.
@njit(cache=True, error_model="numpy", _nrt=False)
def jacobian_step(z, rudder, layout, dt, ship, ws):
    """One RK4 step of the real state z and its exact Jacobian F = d z_next / d z (tangent-linear RK4).

    Same step as :func:`rk4_step` and the same F as :func:`jacobian_step_reference` (to
    rounding), differentiating the RK4 stages instead of the whole step.  With
    x_s = z + a_s dt k_{s-1} (a = 0, 1/2, 1/2, 1) the stage state, k_s = f(x_s) and
    theta = z, for every stage

        d k_s / d theta = A_s (E + a_s dt d k_{s-1} / d theta) + a_delta,s d delta_s / d theta + B_s,

    F = E + dt/6 (dk_1 + 2 dk_2 + 2 dk_3 + dk_4) on the propagated rows (E = [I 0]).

    * A_s = d f / d x over the propagated slots, by complex step of the two parts of
      :func:`mmg.model.rhs`, each along its own arguments only: :func:`mmg.model.dynamics`
      (u, v, r, n rows; in u, v, r, n) and, when x0, y0 or psi are propagated,
      :func:`mmg.model.track` (x0, y0, psi rows; in u, v, r, psi).  One complex evaluation per
      argument, the others left real (so e.g. the hull force stays real under a step in n);
      the real parts give k_s (:func:`_stage_columns`).  Nothing depends on x0, y0: their
      columns are zero.
    * a_delta,s = d f / d delta (with itau >= 0 only; one more evaluation of the dynamics): the
      rudder at stage s is d_s + z[itau] g_s, so d delta_s / d z[itau] = g_s.
    * B_s = d f / d c for the coefficients z[c0 + j] = hull_coef[idx[j]]: analytic
      (:func:`mmg.model.rhs_hull_jacobian`; the hull forces are linear in them).

    Paper filter: 16 complex evaluations of the dynamics a step instead of 64 of rhs; raw-log
    filter 20 (and 16 cheap ones of the track) instead of 80.  With a steady true wind in the packed
    ship (its loads depend on the heading, which :func:`mmg.model.dynamics` does not take) the step is
    :func:`jacobian_step_reference`'s, which carries the wind through :func:`mmg.model.rhs_of`.
    Arguments and outputs as :func:`jacobian_step_reference`: rudder = (d0, d1, g0, g1), layout =
    (slots, c0, idx, itau), ship = (p, poly, hull_axis, hull_term); ws from
    :func:`make_workspace`: z_next = ws[8], F = ws[9].
    """
    d0, d1, g0, g1 = rudder
    slots, c0, idx, itau = layout
    p, _, hull_axis, hull_term = ship
    if p[P_WIND_V] != 0.0:          # a steady wind's loads turn with psi: the whole model's complex step
        jacobian_step_reference(z, rudder, layout, dt, ship, ws)
        return
    z_next, F, hc, xr, kr, ks, dK, dKn, B, w = ws[8], ws[9], ws[10], ws[11], ws[13], ws[14], ws[16], ws[17], \
        ws[18], ws[19]
    nz = z.shape[0]
    ns = slots.shape[0]
    for j in range(idx.shape[0]):
        hc[idx[j]] = z[c0 + j]
    roles = _slot_roles(slots)
    minv = inverse_mass(p, w)
    tau = z[itau] if itau >= 0 else 0.0
    e0 = d0 + tau * g0
    e1 = d1 + tau * g1
    for i in range(8):
        xr[i] = 0.0
    c6 = dt / 6.0
    for i in range(ns):
        ks[i] = 0.0
        for j in range(nz):
            F[i, j] = 1.0 if i == j else 0.0
    for st in range(4):
        a, wst, e, ge = _stage(st, dt, e0, e1, g0, g1)
        # stage state x_s = z + a k_{s-1} (a = a_s dt; its tangent E + a dk_{s-1} enters below)
        for i in range(ns):
            xr[slots[i]] = z[i] + a * kr[i] if st > 0 else z[i]
        xr[DELTA_] = e
        _stage_columns(xr, layout, roles, ship, ws)          # A_s and k_s
        rhs_hull_jacobian(xr, p, hull_axis, hull_term, idx, minv, B)     # B_s, analytic
        # dk_s = A_s (E + a dt dk_{s-1}) + a_delta g_s e_tau + B_s (into dKn; rows of dK contiguous)
        _stage_tangent(st == 0, a, ge, itau, ws[15], dK, dKn)
        dK, dKn = dKn, dK
        _add_hull_columns(B, roles, c0, idx.shape[0], dK)
        cw = c6 * wst
        for i in range(ns):
            ks[i] += wst * kr[i]
            for j in range(nz):
                F[i, j] += cw * dK[i, j]
    for i in range(ns):
        z_next[i] = z[i] + c6 * ks[i]
    _held_rows(z, ns, z_next, F)


@njit(cache=True)
def jacobian_step_reference(z, rudder, layout, dt, ship, ws):
    """:func:`jacobian_step` by brute force: column j of F is Im(step(z + i h e_j)) / h, h = 1e-30.

    One complex RK4 step (:func:`rk4_step`) per column of F (4 nz complex evaluations of f a
    step; complex step: exact to rounding).  The reference for :func:`jacobian_step` (tests,
    ``bench/bench_ekf.py``); same arguments and outputs.
    rudder = (d0, d1, g0, g1): the rudder [rad] d0 -> d1 over the step; with itau >= 0 it is
    d + z[itau] g (g0 -> g1 [rad/s]), z[itau] a timing offset [s] (g = -d(delta)/dt: the rudder
    moved by -tau in time); itau < 0: the rudder is d alone (g ignored).
    layout = (slots, c0, idx, itau): z[i] (i < len(slots)) is the mmg state slots[i], the states
    from len(slots) on are held (rows of F the identity), z[c0 + j] the hull coefficient
    hull_coef[idx[j]].  ship = (p, poly, hull_axis, hull_term) of the packed ship
    (:meth:`mmg.model.PackedShip.args`).  ws from :func:`make_workspace`: z_next = ws[8], F = ws[9].
    """
    d0, d1, g0, g1 = rudder
    slots, _, _, itau = layout
    zc, out, z_next, F = ws[0], ws[7], ws[8], ws[9]
    nz = z.shape[0]
    ns = slots.shape[0]
    for j in range(nz):
        for i in range(nz):
            zc[i] = z[i]
        zc[j] += 1j * CSTEP
        if itau >= 0:
            e0 = d0 + zc[itau] * g0
            e1 = d1 + zc[itau] * g1
        else:
            e0 = d0 + 0j
            e1 = d1 + 0j
        rk4_step(zc, e0, e1, dt, layout, ship, ws)
        for i in range(ns):
            F[i, j] = out[i].imag / CSTEP
        if j == 0:
            for i in range(ns):
                z_next[i] = out[i].real
    _held_rows(z, ns, z_next, F)


@njit(cache=True)
def _dot(a, b):
    """sum_k a[k] b[k], k ascending."""
    acc = 0.0
    for k in range(a.shape[0]):
        acc += a[k] * b[k]
    return acc


@njit(cache=True)
def fpft(F, P, ns, FP, out):
    """out = F P F^T for F = [[A], [0 I]] with A = F[:ns] (the held states' rows the identity).

    FP (nz, nz) is work space; out may be P itself.  Not symmetrised (see :func:`symmetrise`).
    """
    nz = P.shape[0]
    for i in range(ns):
        for j in range(nz):
            FP[i, j] = 0.0
        for k in range(nz):
            f = F[i, k]
            for j in range(nz):
                FP[i, j] += f * P[k, j]
    for i in range(ns, nz):
        for j in range(nz):
            FP[i, j] = P[i, j]
    for i in range(nz):
        for j in range(ns):
            out[i, j] = _dot(FP[i], F[j])
        for j in range(ns, nz):
            out[i, j] = FP[i, j]


@njit(cache=True)
def make_update_workspace(nz, m):
    """Work arrays of :func:`joseph_update_ws` for nz states of which the first m are measured:
    (S, SI, K, KT, KR, y, A)."""
    return (np.empty((m, m)), np.empty((m, m)), np.empty((nz, m)), np.empty((m, nz)), np.empty((nz, m)),
            np.empty(m), np.empty((nz, nz)))


@njit(cache=True)
def _inverse(S, out):
    """out = S^-1 (Gauss-Jordan with partial pivoting; S is overwritten).  Small m only."""
    m = S.shape[0]
    for i in range(m):
        for j in range(m):
            out[i, j] = 1.0 if i == j else 0.0
    for c in range(m):
        piv = c
        for i in range(c + 1, m):
            if abs(S[i, c]) > abs(S[piv, c]):
                piv = i
        if piv != c:
            for j in range(m):
                S[c, j], S[piv, j] = S[piv, j], S[c, j]
                out[c, j], out[piv, j] = out[piv, j], out[c, j]
        d = S[c, c]
        for j in range(m):
            S[c, j] /= d
            out[c, j] /= d
        for i in range(m):
            if i != c:
                f = S[i, c]
                if f != 0.0:
                    for j in range(m):
                        S[i, j] -= f * S[c, j]
                        out[i, j] -= f * out[c, j]


@njit(cache=True)
def joseph_update_ws(z, P, meas, R, uw):
    """Measurement update of z, P with H = [I_m 0] (the first m states measured), Joseph form
    P <- (I - K H) P (I - K H)^T + K R K^T, then P symmetrised; in place.  Returns the NIS y^T S^-1 y.

    The update of :func:`ekf.filter.joseph_update` (same formulas, equal to rounding) without
    its allocations and 16 x 16 matrix products: with H = [I 0], (I - K H) P = P - K P[:m] and
    (I - K H) P (I - K H)^T + K R K^T = A + (K R - A[:, :m]) K^T with A = (I - K H) P.
    uw from :func:`make_update_workspace` (nz, m).
    """
    S, SI, K, KT, KR, y, A = uw
    nz = z.shape[0]
    m = meas.shape[0]
    for i in range(m):
        for j in range(m):
            S[i, j] = P[i, j] + R[i, j]
    _inverse(S, SI)
    for i in range(nz):
        for j in range(m):
            acc = 0.0
            for k in range(m):
                acc += P[i, k] * SI[k, j]
            K[i, j] = acc
            KT[j, i] = acc
    for i in range(m):
        y[i] = meas[i] - z[i]
    nis = 0.0
    for i in range(m):
        for j in range(m):
            nis += y[i] * SI[i, j] * y[j]
    for i in range(nz):
        acc = 0.0
        for j in range(m):
            acc += K[i, j] * y[j]
        z[i] += acc
    # A = P - K P[:m]
    for i in range(nz):
        for j in range(nz):
            A[i, j] = P[i, j]
        for k in range(m):
            kik = K[i, k]
            for j in range(nz):
                A[i, j] -= kik * P[k, j]
    # W = K R - A[:, :m] (into KR), P = A + W K^T, symmetrised
    for i in range(nz):
        for j in range(m):
            acc = 0.0
            for k in range(m):
                acc += K[i, k] * R[k, j]
            KR[i, j] = acc - A[i, j]
    for i in range(nz):
        for j in range(nz):
            P[i, j] = A[i, j]
        for k in range(m):
            wik = KR[i, k]
            for j in range(nz):
                P[i, j] += wik * KT[k, j]
    symmetrise(P, P)
    return nis


@njit(cache=True)
def symmetrise(A, out):
    """out = (A + A^T) / 2 (out may be A itself)."""
    n = A.shape[0]
    for i in range(n):
        for j in range(i, n):
            s = 0.5 * (A[i, j] + A[j, i])
            out[i, j] = s
            out[j, i] = s
