"""The reference for the compiled model's speed: the RK4 integrator of :mod:`mmg.model`
hand-specialised to the Esso Osaka (``configs/ships/esso_osaka.yaml``), all in one function.

Same equations as :func:`mmg.integrate.simulate_kernel` over :func:`mmg.model.rhs`, with
everything a general model cannot assume taken as known for this ship:

* the hull is the Kijima (1990) table of the Esso Osaka (X: r sin(beta), cos(beta)^2;
  Y and N: 1, beta, r, beta|beta|, r|r|, beta^2 r, beta r^2), written out term by term;
* Kijima wake, a constant-power engine, x_G = 0 (diagonal mass matrix);
* every product of ship constants (the force scales, rho D^4, the rudder factors, the
  current's velocity, 1 / masses) computed once before the loop;
* the state held in scalars, the four RK4 stages in one loop, sin/cos(beta) once per stage;
* the low-speed floor (:func:`mmg.model.kinematics`) and the steering gear as in the model; outside
  the first quadrant (propeller astern, ship astern, J > J_MAX: never met on the full-scale trials
  this times) the propeller and the reversed rudder inflow are the model's own compiled functions
  (:func:`mmg.model.propeller`, :func:`mmg.model.rudder_axial_speed`).

It reads the numbers from the packed ship (``p``, ``poly``, ``hull_coef`` of
:func:`mmg.model.pack`), so it agrees with the model to rounding; it is *not* part of the
project (nothing imports it but ``bench/bench_kernel.py``).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from mmg import model as M
from mmg.integrate import (HS_AMP, HS_FIRST, HS_HI, HS_LO, HS_PSI0, HS_TRIM, HS_TSTART,
                           SCHEDULE)

# the Esso Osaka hull table, in the order of configs/ships/esso_osaka.yaml
HULL_NAMES = ("X_br", "X_uu", "Y_0", "Y_beta", "Y_r", "Y_bb", "Y_rr", "Y_bbr", "Y_brr",
              "N_0", "N_beta", "N_r", "N_bb", "N_rr", "N_bbr", "N_brr")


def check_ship(ship, packed) -> None:
    """Raise ValueError unless ``ship`` / ``packed`` is a ship this kernel is specialised to."""
    p = packed.p
    if tuple(ship.hull.names) != HULL_NAMES:
        raise ValueError(f"hull table {ship.hull.names} is not the Esso Osaka's")
    if p[M.P_WAKE] != M.WAKE_KIJIMA or p[M.P_ENGINE] != M.ENGINE_CONSTANT_POWER or p[M.P_XG] != 0.0:
        raise ValueError("kernel is specialised to Kijima wake, constant power and x_G = 0")
    if p[M.P_YP_ASTERN] != 0.0:
        raise ValueError("kernel has no propeller walk astern (propeller.Y_P_astern must be 0)")
    if p[M.P_HULL_ASTERN] != 0.0:
        raise ValueError("kernel takes the hull astern as ahead (hull.astern must be as_ahead)")


@njit(cache=True, error_model="numpy", nogil=True)
def reference_kernel(x0, dt, nsteps, p, poly, hull_coef, kind, cpar, st, sd, sn, states, orders):
    """RK4 of the Esso Osaka MMG model; the arguments and the result of
    :func:`mmg.integrate.simulate_kernel` (without the hull's axis and term tables)."""
    # ---------------------------------------------------------------- constants, once
    rho, L, T = p[M.P_RHO], p[M.P_L], p[M.P_T]
    D = p[M.P_D]
    ul = p[M.P_ULOW]
    inv2ul = 1.0 / (2.0 * ul)
    fsc = 0.5 * rho * L * T
    msc = 0.5 * rho * L * L * T
    xP, Cw = p[M.P_XP], p[M.P_CWAKE]
    rhoD4 = rho * D ** 4
    rhoD5 = rho * D ** 5
    kq_scale = p[M.P_KQSCALE]
    tw0, tw1, tw2, tw3 = poly[M.POLY_WP0, 0], poly[M.POLY_WP0, 1], poly[M.POLY_WP0, 2], poly[M.POLY_WP0, 3]
    tp0, tp1, tp2, tp3 = poly[M.POLY_TP, 0], poly[M.POLY_TP, 1], poly[M.POLY_TP, 2], poly[M.POLY_TP, 3]
    kt0, kt1, kt2, kt3 = poly[M.POLY_KT, 0], poly[M.POLY_KT, 1], poly[M.POLY_KT, 2], poly[M.POLY_KT, 3]
    kq0, kq1, kq2 = poly[M.POLY_KQ, 0], poly[M.POLY_KQ, 1], poly[M.POLY_KQ, 2]
    jmax = M.J_MAX
    offset = p[M.P_RUDDER_OFFSET]
    kap, eps, eta = p[M.P_KAPPA], p[M.P_EPS], p[M.P_ETA]
    one_kap, one_eta = 1.0 - kap, 1.0 - eta
    eight_pi = 8.0 / np.pi
    lR, gpos, gneg = p[M.P_LR], p[M.P_GPOS], p[M.P_GNEG]
    fn_c = 0.5 * rho * p[M.P_AR] * p[M.P_FALPHA]
    xr_c = -(1.0 - p[M.P_TR])
    yr_c = -(1.0 + p[M.P_AH])
    nr_c = -(p[M.P_XR] + p[M.P_AH] * p[M.P_XH])
    ext_x, ext_y, ext_n = p[M.P_EXT_X], p[M.P_EXT_Y], p[M.P_EXT_N]
    m, mx, my = p[M.P_M], p[M.P_MX], p[M.P_MY]
    mmx, mmy = m + mx, m + my
    izz = p[M.P_IZ] + p[M.P_JZ]
    two_pi = 2.0 * np.pi
    power = p[M.P_POWER]
    shaft = 2.0 * np.pi * p[M.P_SHAFT_I]
    cur_x = p[M.P_CUR_SPEED] * np.cos(p[M.P_CUR_DIR])
    cur_y = p[M.P_CUR_SPEED] * np.sin(p[M.P_CUR_DIR])
    te, rate, dmax = p[M.P_TE], p[M.P_RATE], p[M.P_DMAX]
    te_rate = te * rate
    X_br, X_uu = hull_coef[0], hull_coef[1]
    Y_0, Y_b, Y_r, Y_bb, Y_rr, Y_bbr, Y_brr = (hull_coef[2], hull_coef[3], hull_coef[4], hull_coef[5],
                                               hull_coef[6], hull_coef[7], hull_coef[8])
    N_0, N_b, N_r, N_bb, N_rr, N_bbr, N_brr = (hull_coef[9], hull_coef[10], hull_coef[11], hull_coef[12],
                                               hull_coef[13], hull_coef[14], hull_coef[15])
    half_dt, dt6 = 0.5 * dt, dt / 6.0

    # ---------------------------------------------------------------- state and command law
    u, v, r, x, y, psi, delta, n = x0[0], x0[1], x0[2], x0[3], x0[4], x0[5], x0[6], x0[7]
    side = cpar[HS_FIRST]
    ptr = 0
    nt = st.shape[0]
    u_min = 0.01 * abs(x0[0])
    # stage derivatives (assigned in the stage loop before use)
    du = dv = dr = dx = dy = dpsi = dd = dn = 0.0
    for i in range(nsteps + 1):
        t = i * dt
        if kind == SCHEDULE:                       # the model's _interp, rudder column only
            while ptr < nt - 2 and st[ptr + 1] <= t:
                ptr += 1
            if t <= st[0]:
                dcmd = sd[0]
            elif t >= st[nt - 1]:
                dcmd = sd[nt - 1]
            else:
                w = (t - st[ptr]) / (st[ptr + 1] - st[ptr])
                dcmd = sd[ptr] + w * (sd[ptr + 1] - sd[ptr])
        else:
            if t < cpar[HS_TSTART]:
                dcmd = cpar[HS_TRIM]
            else:
                dpsi0 = psi - cpar[HS_PSI0]
                if side > 0.0 and dpsi0 >= cpar[HS_HI]:
                    side = -1.0
                elif side < 0.0 and dpsi0 <= cpar[HS_LO]:
                    side = 1.0
                dcmd = side * cpar[HS_AMP]
        states[i, 0] = u
        states[i, 1] = v
        states[i, 2] = r
        states[i, 3] = x
        states[i, 4] = y
        states[i, 5] = psi
        states[i, 6] = delta
        states[i, 7] = n
        orders[i] = dcmd
        if not (u > u_min) or np.isnan(psi):
            return i
        if i == nsteps:
            break
        cmd = min(max(dcmd, -dmax), dmax)
        su = sv = sr = sx = sy = spsi = sd_ = sn_ = 0.0
        for s in range(4):
            c = 0.0 if s == 0 else (half_dt if s < 3 else dt)
            us, vs, rs = u + c * du, v + c * dv, r + c * dr
            psis, ds, ns = psi + c * dpsi, delta + c * dd, n + c * dn
            # kinematics with the low-speed floor
            U = np.sqrt(us * us + vs * vs)
            if U >= ul:
                Uh = U
                beta = np.arctan(-vs / (us if us >= 0.0 else -us))
            else:
                Uh = (U * U + ul * ul) * inv2ul
                beta = np.arctan(-vs / np.sqrt(Uh * Uh - vs * vs))
            rp = rs * L / Uh
            sb, cb = np.sin(beta), np.cos(beta)
            ab = beta if beta >= 0.0 else -beta
            arp = rp if rp >= 0.0 else -rp
            bb, rr = beta * ab, rp * arp
            bbr, brr = beta * beta * rp, beta * rp * rp
            XH = X_br * (rp * sb) + X_uu * (cb * cb)
            YH = Y_0 + Y_b * beta + Y_r * rp + Y_bb * bb + Y_rr * rr + Y_bbr * bbr + Y_brr * brr
            NH = N_0 + N_b * beta + N_r * rp + N_bb * bb + N_rr * rr + N_bbr * bbr + N_brr * brr
            k = U * Uh
            if us >= ul:
                ss = 1.0
            elif us <= -ul:
                ss = -1.0
            else:
                ss = us / ul
            # wake and propeller
            w0 = ((tw3 * us + tw2) * us + tw1) * us + tw0
            bp = beta - xP * rp
            owp = 1.0 - w0 * np.exp(-Cw * bp * bp)
            uP = us * owp
            tP = ((tp3 * us + tp2) * us + tp1) * us + tp0
            nD = ns * D
            if ns >= 0.0 and uP >= 0.0 and nD * jmax > uP:
                J = uP / nD
                KT = ((kt3 * J + kt2) * J + kt1) * J + kt0
                XP = (1.0 - tP) * rhoD4 * ns * ns * KT
                TL = eight_pi * KT * nD * nD
            else:                                       # the four quadrants: the model's own
                J, XP, TL = M.propeller(us, ns, owp, p, poly)
            # rudder
            dr_ = ds + offset
            bR = beta - lR * rp
            vR = U * (gpos if bR >= 0.0 else gneg) * bR
            if ns >= 0.0 and us >= 0.0:
                q2 = uP * uP + TL
                q = np.sqrt(q2) if q2 > 0.0 else 0.0
                uPs = one_kap * uP + kap * q
                uR = eps * np.sqrt(eta * uPs * uPs + one_eta * uP * uP)
                if uR > 1e-12:
                    alpha = dr_ - np.arctan(vR / uR)
                else:
                    alpha = dr_ - (np.pi / 2 if vR > 0.0 else -np.pi / 2 if vR < 0.0 else 0.0)
            else:                                       # reversed inflow: the model's own
                uR = M.rudder_axial_speed(uP if us >= 0.0 else us, TL, p)
                alpha = dr_ - M.atan2_of(vR, uR)
            FN = fn_c * (uR * uR + vR * vR) * np.sin(alpha)
            cdr = np.cos(dr_)
            Xt = XH * fsc * k * ss + XP + xr_c * FN * np.sin(dr_) + ext_x
            Yt = YH * fsc * k + yr_c * FN * cdr + ext_y
            Nt = NH * msc * k + nr_c * FN * cdr + ext_n
            # equations of motion (x_G = 0), shaft, track, steering gear
            du = (Xt + mmy * vs * rs) / mmx
            dv = (Yt - mmx * us * rs) / mmy
            dr = Nt / izz
            KQ = kq_scale * ((kq2 * J + kq1) * J + kq0)
            dn = (-rhoD5 * ns * ns * KQ + power / (two_pi * ns)) / shaft
            cp, sp = np.cos(psis), np.sin(psis)
            dx = us * cp - vs * sp + cur_x
            dy = us * sp + vs * cp + cur_y
            dpsi = rs
            err = cmd - ds
            if abs(err) <= te_rate:
                dd = err / te
            else:
                dd = rate if err > 0.0 else -rate
            wgt = 1.0 if (s == 0 or s == 3) else 2.0
            su += wgt * du
            sv += wgt * dv
            sr += wgt * dr
            sx += wgt * dx
            sy += wgt * dy
            spsi += wgt * dpsi
            sd_ += wgt * dd
            sn_ += wgt * dn
        u += dt6 * su
        v += dt6 * sv
        r += dt6 * sr
        x += dt6 * sx
        y += dt6 * sy
        psi += dt6 * spsi
        delta += dt6 * sd_
        n += dt6 * sn_
        du = dv = dr = dx = dy = dpsi = dd = dn = 0.0
    return nsteps + 1
