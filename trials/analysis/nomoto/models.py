"""Linear Nomoto steering models: parameters and their YAML files.

Models (dimensionless distance form of Artyszuk 2018, see :mod:`trials.analysis.nomoto`)

* 1st order, eq. (1):  T domega'/ds' + omega' = K delta
* 2nd order, eq. (13): T1 T2 d2omega'/ds'^2 + (T1 + T2) domega'/ds' + omega'
  = K (delta + T3 ddelta/ds')

K, T, T1, T2, T3 are dimensionless (the T's in ship lengths).

This is the bottom layer of the package: it imports nothing from the other
:mod:`trials.analysis.nomoto` modules.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from mmg.errors import InputError

__all__ = ["NomotoModel", "first_order", "load_model", "zigzag_spec"]


@dataclass(frozen=True)
class NomotoModel:
    """Parameters of a linear Nomoto model (dimensionless, distance form).

    Parameters
    ----------
    K : float
        Gain constant [-]: steady dimensionless yaw rate per radian of rudder.
    T1 : float
        First (largest) distance constant [-] (ship lengths).  For a first-order
        model this is Nomoto's T.
    T2 : float
        Second distance constant [-]; 0 for a first-order model.
    T3 : float
        Rudder-rate (zero) distance constant [-]; 0 for a first-order model.
    name : str
        Label used in reports.
    """

    K: float
    T1: float
    T2: float = 0.0
    T3: float = 0.0
    name: str = ""

    @property
    def order(self) -> int:
        """1 when T2 = T3 = 0 (eq. 1), else 2 (eq. 13)."""
        return 1 if (self.T2 == 0.0 and self.T3 == 0.0) else 2

    @property
    def T(self) -> float:
        """Equivalent first-order constant T = T1 + T2 - T3, eq. (26)."""
        return self.T1 + self.T2 - self.T3

    def to_dict(self) -> dict:
        """Plain dict of the parameters, with ``order`` added."""
        d = asdict(self)
        d["order"] = self.order
        return d

    def to_pandas(self):
        """The parameters as a one-row DataFrame."""
        import pandas as pd

        return pd.DataFrame([self.to_dict()])


def first_order(K: float, T: float, name: str = "") -> NomotoModel:
    """A first-order model, eq. (1).

    Parameters
    ----------
    K : float
        Gain [-].
    T : float
        Distance constant [-].
    name : str
        Label.

    Returns
    -------
    NomotoModel
        With T1 = T and T2 = T3 = 0.
    """
    return NomotoModel(K=float(K), T1=float(T), T2=0.0, T3=0.0, name=name)


def _params_from_x(x):
    """(K, T1, T2, T3, real) from x1 = T1 T2, x2 = T1 + T2, x3 = -K, x4 = -K T3 (eqs. 16, 23).

    T1, T2 are NaN when (T1 + T2)^2 < 4 T1 T2 (no real roots); ``real`` tells which.
    Shared by the four-point method and the whole-record fits.
    """
    disc = x[1] ** 2 - 4 * x[0]
    r = np.sqrt(disc) if disc >= 0 else np.nan
    return -x[2], 0.5 * (x[1] + r), 0.5 * (x[1] - r), x[3] / x[2], disc >= 0


def load_model(path) -> NomotoModel:
    """Read a Nomoto model from YAML.

    The parameters ``K`` and either ``T`` (first order) or ``T1``, ``T2``, ``T3``
    (second order), all dimensionless, sit under a ``model:`` mapping (or at the
    top level of the file); an optional top-level ``name`` labels the model
    (default: the file's stem).  A ``zigzag:`` mapping may hold the test
    settings, see :func:`zigzag_spec`.

    Parameters
    ----------
    path : str or Path
        YAML file, e.g. ``configs/nomoto/artyszuk_eq24.yaml``.

    Returns
    -------
    NomotoModel
        First order when the file gives ``T``, else second order.

    Raises
    ------
    InputError
        Missing, non-numeric or non-finite parameters.
    """
    import yaml

    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as err:
        raise InputError(str(path), "", f"cannot read Nomoto parameters ({err})") from None
    if not isinstance(data, dict):
        raise InputError(str(path), "", "expected a mapping of Nomoto parameters")
    model = data.get("model", data)

    def num(key):
        if key not in model:
            raise InputError(str(path), key, "missing")
        try:
            v = float(model[key])
        except (TypeError, ValueError):
            raise InputError(str(path), key, f"not a number: {model[key]!r}") from None
        if not np.isfinite(v):
            raise InputError(str(path), key, "not finite")
        return v

    name = str(data.get("name", path.stem))
    if "T" in model:
        return first_order(num("K"), num("T"), name=name)
    return NomotoModel(num("K"), num("T1"), num("T2"), num("T3"), name=name)


def zigzag_spec(path) -> dict:
    """Zigzag settings stored next to the model in a YAML file (all optional).

    Keys of the ``zigzag:`` mapping: ``delta0_deg`` (rudder angle, default 10),
    ``psi0_deg`` (check heading, default = delta0_deg), ``rudder_rate_deg_per_L``
    (default 23, Artyszuk's reference rate), ``s_max`` (default 14), ``ds``
    (output step, default 0.001).

    Parameters
    ----------
    path : str or Path
        YAML file.

    Returns
    -------
    dict
        All five keys, defaults filled in (plus any other keys of the mapping);
        the keyword arguments of :func:`trials.analysis.nomoto.simulation.simulate_zigzag`.
    """
    import yaml

    data = yaml.safe_load(Path(path).read_text()) or {}
    z = dict(data.get("zigzag", {}))
    z.setdefault("delta0_deg", 10.0)
    z.setdefault("psi0_deg", z["delta0_deg"])
    z.setdefault("rudder_rate_deg_per_L", 23.0)
    z.setdefault("s_max", 14.0)
    z.setdefault("ds", 0.001)
    return z


