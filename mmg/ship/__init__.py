"""Ship data: frozen dataclasses in SI, loaded and validated from YAML, as a package of rooms whose public
names it re-exports: :mod:`.data` the dataclasses (:class:`Ship` and its parts), :mod:`.load` the YAML
schema, the unit conversion and bounds of every field and :func:`load_ship` (its docstring lists the
symbols), :mod:`.yamlfile` the reading of a config file (:func:`read_yaml`: size, duplicate keys, one-line
messages).
"""
from __future__ import annotations

from .data import (Particulars, MassProperties, HullModel, Propeller, Rudder, SteeringGear, Engine, Wind,
                   ParameterCovariance, FullScale, IdentificationNotes, RunSpread, ModelForm, Ship)
from .yamlfile import one_line, field_path, MAX_CONFIG_BYTES, parse_yaml, read_yaml, ConfigError
from .load import Length, Quantity, pydantic_message, ship_from_dict, load_ship

