"""Linear Nomoto steering models and their identification from zigzag tests.

Everything here is in the fully dimensionless form of Artyszuk (2018), "A study
on the identification of the second-order linear Nomoto model from the zigzag
test", Sci. J. Maritime Univ. Szczecin 53(125), 59-67:

* s' = t U / L            dimensionless distance (ship lengths travelled), eq. (2)
* omega' = dpsi/ds' = r L / U          dimensionless yaw rate, eq. (3)
* eps' = domega'/ds' = rdot L^2 / U^2  dimensionless yaw acceleration, eq. (4)
* Delta(s') = integral_0^s' delta ds'  rudder integral [rad], eq. (6)

Models
    1st order, eq. (1):  T domega'/ds' + omega' = K delta
    2nd order, eq. (13): T1 T2 d2omega'/ds'^2 + (T1 + T2) domega'/ds' + omega'
                             = K (delta + T3 ddelta/ds')

K, T, T1, T2, T3 are dimensionless (T in ship lengths).  Angles are radians,
rudder positive to starboard, heading positive clockwise (to starboard), so a
stable ship has K > 0.

Identification methods (all work on the *integrated* model, eqs. (5)/(14)):

* :func:`classical_first_order` - Nomoto (1960), eqs. (10)-(12), per half-cycle.
* :func:`four_point` - Artyszuk's four-point 2nd-order method, eqs. (15)-(18), (23),
  with the Cramer determinants of his Table 7.
* :func:`fit_least_squares` - eq. (15), by default integrated twice so that only
  the recorded heading and rudder enter, fitted to every sample (beyond the paper).
* :func:`fit_output_error` - the ODE simulated with the recorded rudder and fitted
  to the whole heading history (beyond the paper).
* :func:`identify` - all of them on one record.

Modules, each importing only from those listed before it:

=============================================  ==========================================================
:mod:`~trials.analysis.nomoto.models`          :class:`NomotoModel`, :func:`first_order`, YAML loading
:mod:`~trials.analysis.nomoto.points`          :class:`ZigzagPoints`, the values at CR1, OS1, CR2, OS2
:mod:`~trials.analysis.nomoto.response`        :func:`simulate_response`, exact response to a sampled rudder
:mod:`~trials.analysis.nomoto.simulation`      trapezoidal zigzag rudder, :func:`simulate_zigzag`
:mod:`~trials.analysis.nomoto.smoothing`       :func:`smooth_derivatives`, the spline differentiator
:mod:`~trials.analysis.nomoto.zigzag`          :func:`zigzag_data`, a record's zigzag in s'
:mod:`~trials.analysis.nomoto.fourpoint`       :func:`four_point` and :class:`FourPointResult`
:mod:`~trials.analysis.nomoto.classical`       :func:`classical_first_order` and :class:`ClassicalResult`
:mod:`~trials.analysis.nomoto.least_squares`   :func:`fit_least_squares` and :class:`FitResult`
:mod:`~trials.analysis.nomoto.output_error`    :func:`fit_output_error`
:mod:`~trials.analysis.nomoto.identification`  :func:`identify`, :func:`heading_rms`, :class:`NomotoIdentification`
=============================================  ==========================================================

The package is pure numerics: it imports neither matplotlib nor the CLI (the plot
is :mod:`trials.analysis.nomoto_plot`, the paper's tables :mod:`trials.papers.artyszuk`, the
``mmg nomoto`` commands are registered in :mod:`trials.cli`).  Use the names re-exported here
(``from trials import nomoto as nm; nm.identify(...)``); the module layout is
described in ``docs/nomoto.md``.
"""
from __future__ import annotations

from trials.analysis.nomoto.classical import ClassicalResult, classical_first_order
from trials.analysis.nomoto.fourpoint import FourPointResult, four_point
from trials.analysis.nomoto.identification import NomotoIdentification, fit_problem, heading_rms, identify
from trials.analysis.nomoto.least_squares import Z95, FitResult, fit_least_squares
from trials.analysis.nomoto.models import NomotoModel, first_order, load_model, zigzag_spec
from trials.analysis.nomoto.output_error import fit_output_error
from trials.analysis.nomoto.points import ZigzagPoints
from trials.analysis.nomoto.response import simulate_response
from trials.analysis.nomoto.simulation import ZigzagSimulation, simulate_zigzag, trapezoid_knots, trapezoid_rudder
from trials.analysis.nomoto.smoothing import smooth_derivatives
from trials.analysis.nomoto.zigzag import ZigzagData, approach_speed, zigzag_data

__all__ = [
    # models
    "NomotoModel", "first_order", "load_model", "zigzag_spec",
    # points, simulation, response
    "ZigzagPoints", "trapezoid_knots", "trapezoid_rudder", "ZigzagSimulation", "simulate_zigzag",
    "simulate_response",
    # records
    "smooth_derivatives", "ZigzagData", "approach_speed", "zigzag_data",
    # identification
    "FourPointResult", "four_point", "ClassicalResult", "classical_first_order",
    "Z95", "FitResult", "fit_least_squares", "fit_output_error",
    "heading_rms", "fit_problem", "NomotoIdentification", "identify",
]
