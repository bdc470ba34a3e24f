"""The units block and the producing version of every JSON document rockmech writes.

Every document (``--json`` of each command, the files beside a run, REST and Hops answers)
carries ``rockmech_version`` (``shared_schema.version.__version__``) and ``units``: the unit
of each quantity whose name does not say it (a name ending in ``_g``, ``_s``, ``_m``,
``_hz`` states its unit itself; ``-`` is dimensionless). The kinematic-constants file
carries the same two (``ConstantsFile.units``, ``ConstantsFile.rockmech_version``).

``DOCUMENT_UNITS`` is the one home of these blocks; ``stamp`` adds one to a document, and
``finite_json`` makes a document JSON-ready (no NaN, no numpy scalars) before it is printed or
written.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from shared_schema.documents.base import Part
from shared_schema.retrofit_units import RETROFIT_UNITS
from shared_schema.version import __version__

__all__ = ["DOCUMENT_UNITS", "VERSION_KEY", "finite_json", "stamp"]

#: Key of the producing version in every document.
VERSION_KEY = "rockmech_version"

_TIMES = {"t_peak": "s", "t_overturn": "s", "runtime_s": "s"}
_MECHANISM = {"p_eq": "rad/s", "lam": "-", "phi_ov": "rad", "eta": "-"}
_SPECTRUM = {"periods_s": "s", "psa_g": "g", "sd_m": "m", "damping": "-"}
_RECORD = {"dt_s": "s", "pga_g": "g", "duration_s": "s"}
_PULSE = {"a_p_g": "g", "f_p": "Hz", "f_p_hz": "Hz", "t_start_s": "s", "duration": "s"}

#: The units of each kind of document.
DOCUMENT_UNITS: dict[str, dict[str, str]] = {
    "pulse": {
        **_MECHANISM,
        "a_p_g": "g",
        "f_p": "Hz",
        "omega_ratio": "-",
        "amplitude_ratio": "-",
        "peak_ratio": "-",
        "error_estimate": "-",
        **_TIMES,
    },
    "envelope": {
        "f_p": "Hz",
        "a_p": "g",
        "a_p_min_g": "g",
        "a_p_min_local_g": "g",
        "scale_factor": "-",
        "f_min": "Hz",
        "f_max": "Hz",
        "f_low": "Hz",
        "f_high": "Hz",
        "f_n": "Hz",
        "h": "m",
        "h_e": "m",
        **_MECHANISM,
    },
    "history": {
        "scale": "-",
        "effective_scale": "-",
        "peak_ratio": "-",
        "error_estimate": "-",
        "peak_displacement_m": "m",
        **_RECORD,
        **_TIMES,
    },
    "record": {**_RECORD, **_SPECTRUM, **_PULSE, "runtime_s": "s"},
    "boundary": {"omega": "-", "eta": "-", "overturning_intervals": "-", "scan_ratio": "-"},
    "ida": {"levels": "the intensity measure's (intensity.units)", "fraction": "-"},
    "scale_factor": {"value": "-", "h": "m", "h_e": "m", "z": "m", "H": "m", "f_n": "Hz"},
    "check": {
        "T": "s",
        "T1": "s",
        "T_B": "s",
        "T_C": "s",
        "T_D": "s",
        "Ts": "s",
        "a0_star": "m/s2",
        "a_star": "m/s2",
        "as_star": "m/s2",
        "d_star": "m",
        "d0_star": "m",
        "ds_star": "m",
        "du_star": "m",
        "linear.demand": "m/s2",
        "nonlinear.demand": "m",
        "M_star": "kg",
        "height": "m",
        "Z": "m",
        "alpha0": "-",
        "e_star": "-",
        "capacity_ratio": "-",
    },
    "health": {"compute_timeout_s": "s"},
    "search": {
        "length": "m",
        "mass": "kg",
        "force": "N",
        "f_p": "Hz",
        "a_p": "g",
        "angle": "rad",
    },
}
DOCUMENT_UNITS["retrofit"] = dict(RETROFIT_UNITS)
DOCUMENT_UNITS["assess"] = {
    **DOCUMENT_UNITS["check"],
    **DOCUMENT_UNITS["history"],
    "multiples": "-",
    "f_p": "Hz",
    "a_p_g": "g",
}


def stamp(doc: dict[str, Any], kind: str) -> dict[str, Any]:
    """Return ``doc`` with ``rockmech_version`` and the ``units`` of its kind, first.

    Units the document already gives are kept (they win over the defaults); a document
    stamped twice is unchanged.

    Examples
    --------
    >>> out = stamp({"f_p": [1.0]}, "envelope")
    >>> list(out)[:2], out["units"]["f_p"]
    (['rockmech_version', 'units'], 'Hz')
    """
    units = {**DOCUMENT_UNITS[kind], **doc.get("units", {})}
    rest = {k: v for k, v in doc.items() if k not in ("units", VERSION_KEY)}
    return {VERSION_KEY: doc.get(VERSION_KEY, __version__), "units": units, **rest}


def finite_json(value: Any) -> Any:
    """Replace non-finite floats by None and numpy scalars by Python numbers, recursively.

    ``json.dumps`` never calls ``default`` for floats, so NaN and infinity must be cleaned
    before serialising (``allow_nan=False`` then guards the result). A typed document
    (``shared_schema.documents``) gives its JSON form, ``to_dict()``.
    """
    if isinstance(value, Part):
        return value.to_dict()
    if isinstance(value, dict):
        return {str(k): finite_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_json(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
