"""Plot of a zigzag record with the identified Nomoto models (matplotlib, Agg backend)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from trials.analysis import nomoto as nm


def plot_identification(ident: "nm.NomotoIdentification", path) -> Path:
    """Zigzag plot: measured heading and rudder, the four points, and the fitted models' headings.

    Upper panel: heading and rudder [deg] against s' = t U/L [-] (top axis time
    after the execute [s]); CR1, OS1, CR2, OS2 marked; the headings simulated
    from the execute with the recorded rudder by the classical 1st-order model,
    the four-point, least-squares and output-error 2nd-order models; a fit that
    is unusable (:func:`trials.analysis.nomoto.fit_problem`) is not drawn, its
    legend entry says why.  Lower
    panel: omega' and eps' used by the point methods.

    Parameters
    ----------
    ident : NomotoIdentification
        Result of :func:`trials.analysis.nomoto.identify`.
    path : str or Path
        PNG file to write.
    """
    import textwrap

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    z = ident.zigzag
    path = Path(path)
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(14, 7.5), sharex=True, gridspec_kw={"height_ratios": [3, 1.4]})
    sign = z.sign
    psi_rec = z.psi if z.psi_raw is None else z.psi_raw
    ax.plot(z.s, np.degrees(psi_rec), color="k", lw=2.2, label="heading, measured")
    ax.plot(z.s, np.degrees(z.delta + z.delta_e), color="0.55", lw=1.2, ls="-", label="rudder, measured")
    colours = {"first_order": "tab:orange", "four_point": "tab:blue", "least_squares": "tab:green",
               "output_error": "tab:red"}
    lim = float(np.max(np.abs(np.degrees(psi_rec))))
    for key, (label, m, db) in ident.fits().items():
        c = colours[key]
        if not ident.usable(key):                 # a failed fit is named, not drawn as a result
            why = textwrap.fill(ident.problems[key], 48, initial_indent="  ", subsequent_indent="  ")
            ax.plot([], [], color=c, ls=":", label=f"{label}: UNUSABLE, not drawn\n{why}")
            continue
        init = getattr(ident.output_error, "initial_state", None) if key == "output_error" else None
        psi0, w0, e0 = init if init is not None else (0.0, z.omega_e, z.eps_e)
        psi = nm.simulate_response(m, z.s, z.delta + z.delta_e, psi0, w0, e0, db)
        rms = np.degrees(np.sqrt(np.mean((psi - psi_rec) ** 2)))
        ax.plot(z.s, np.degrees(psi), color=c, ls="--", lw=1.3, label=f"{label} (RMS {rms:.2f} deg)")
    p = ident.points
    ax.plot(p.s, np.degrees(p.psi), "o", ms=8, mfc="none", mec="m", mew=2, label="four points")
    for nmn, s_, ps in zip(p.names, p.s, p.psi):
        ax.annotate(nmn, (s_, np.degrees(ps)), textcoords="offset points", xytext=(5, 6), color="m")
    ax.axhline(0, color="0.8", lw=0.8)
    ax.set_ylim(-1.6 * lim, 1.6 * lim)
    flip = "" if sign > 0 else " (signs flipped: first execute to port)"
    ax.set_ylabel("heading change, rudder [deg]" + flip)
    ax.set_title(f"{z.name}: zigzag, Nomoto identification (L = {z.L:g} m, U = {z.U:.3g} m/s)")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.grid(alpha=0.3)
    ax2.plot(z.s, z.omega, label="omega' [-]")
    ax2.plot(z.s, z.eps, label="eps' [-]")
    ax2.plot(p.s, p.omega + np.where([n.startswith("CR") for n in p.names], z.omega_e, 0.0), "o", mfc="none", mec="m")
    ax2.set_xlabel("s' = t U / L [-] (ship lengths after the execute)")
    ax2.set_ylabel("omega', eps' [-]")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    sec = ax.secondary_xaxis("top", functions=(lambda s: s * z.L / z.U, lambda t: t * z.U / z.L))
    sec.set_xlabel("time after execute [s]")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
