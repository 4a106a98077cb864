"""Output-error (maximum-likelihood) refinement of the sway/yaw hull coefficients.

The augmented EKF (:mod:`ekf.filter`) gives a first estimate; this module refines it by
simulating every trial with the simulator's own compiled model (:func:`mmg.integrate.integrate`
on a copy of the packed ship whose ``hull_coef`` slots hold the candidate derivatives, no
second physics copy) and minimising the weighted residuals against the *raw* 5 s log samples
(no interpolation, no differentiation):

    J(theta) = sum_trials sum_k  sum_{c in psi, x, y, n} ((c_sim(t_k; theta) - c_log(t_k)) / sigma_c)^2

jointly over several trials, with :func:`scipy.optimize.least_squares` (trust-region).
``sigma_c`` is the log's noise standard deviation (uniform noise of half-width a has
sigma = a / sqrt(3); the half-widths are read from the log header, Rhee & Kim Table 4
otherwise), so the weights are the inverse noise variances and (J^T W J)^-1 at the optimum
is the (Gaussian-approximation) Cramér-Rao covariance of the estimate: the standard errors
reported beside each derivative.

Per trial the unknown start is estimated too (nuisance parameters): the sway speed v0 and
the start heading/position psi0, x0, y0 (their Jacobian columns are analytic: a shift, and
a rotation of the track about the start point).  u0, n0 and the trim rudder come from the
log header (the steady approach).  The rudder is driven by

* ``rudder="ramp"`` (default): turning trials their constant order; zigzag / S-type trials an
  open-loop order whose reversal times t_k are continuous nuisance parameters too, started where
  the recovered heading reaches the switching heading (:meth:`OETrial.ramp_law`: the step holding
  t_k gets the order that moves the rate-limited rudder by the matching fraction of a full-rate
  step, so the cost is continuous in t_k and the derivatives no longer have to make up for
  whole-step switch errors). A per-trial pre-fit of the nuisances at the start derivatives
  (:func:`fit_nuisance`) precedes the joint fit;
* ``rudder="law"``: the trial's own closed-loop law (heading switch on the *simulated* heading);
  the cost jumps whenever a simulated switch moves a step (the fit stops in a wrong cell), or
* ``rudder="reconstructed"``: the order rebuilt from the recovered heading as an open-loop
  schedule with whole-step switches (searched greedily; some stay one step off).

Derivative Jacobian columns are forward differences (one simulation per derivative and trial);
simulations of one Jacobian run on ``n_jobs`` threads (the compiled integration releases the GIL).

Modules: :mod:`~ekf.output_error.trial` (one trial: start, rudder command, simulated
residuals), :mod:`~ekf.output_error.switches` (whole-step switch search of a rebuilt
rudder), :mod:`~ekf.output_error.fit` (the joint least-squares problem, its Jacobian and
the EKF start).  The Monte Carlo is :func:`trials.estimates.montecarlo.output_error_monte_carlo`
(``mmg output-error OUT --seeds 20``).
"""
from __future__ import annotations

from .fit import OEEstimate, OEResult, fit, fit_nuisance, information, refine
from .switches import search_switches, switches
from .trial import CH, FD_STEP, NNUIS, OETrial, trial_from_data

__all__ = ["OETrial", "trial_from_data", "OEResult", "OEEstimate", "fit", "fit_nuisance", "information",
           "refine", "switches", "search_switches", "CH", "NNUIS", "FD_STEP"]
