"""The pulse analysis: one mechanism under a one-cycle pulse (``rockmech pulse``, REST ``/pulse``).

Apart from the other documents (``documents``) so that a pulse loads the exact solver and
no more: no envelope, no spectrum, no scipy.optimize (``rockmech pulse`` starts fast, #38).
Units: ``a_p_g`` in g, ``f_p`` in Hz, SI otherwise.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any, Optional, Union

from pydantic import ValidationError

from shared_schema.constants import ConstantsFile, input_error_from_validation
from shared_schema.documents.pulse import PulseDocument
from shared_schema.errors import InputError, wrong_type
from shared_schema.pulse_request import PulseRequest

from ..core.exact import simulate
from ..core.excitation import Pulse
from ..core.model import RockingModel
from .adapter import to_rocking_model
from .units import stamp

__all__ = ["pick_mechanism", "pulse_model", "solve_pulse"]


def pulse_model(request: PulseRequest) -> RockingModel:
    """Return the mechanism of a pulse request as the solver's model.

    The short form is a symmetric mechanism named ``pulse``; ``mechanism`` is converted as
    every analysis converts a constants file's mechanism (``adapter.to_rocking_model``).
    """
    if request.mechanism is not None:
        return to_rocking_model(request.mechanism)
    if request.p_eq is None or request.lam is None:  # the request model refuses this
        raise InputError("required, unless the mechanism is given", "p_eq")
    return RockingModel.symmetric(
        request.p_eq,
        request.lam,
        request.eta,
        phi_ov=request.phi_ov,
        one_sided=request.one_sided,
        name="pulse",
    )


def pick_mechanism(cf: ConstantsFile, mechanism: Optional[str] = None) -> dict[str, Any]:
    """One mechanism of a constants file as the ``mechanism`` of a pulse request (JSON data).

    Parameters
    ----------
    cf : ConstantsFile
        The file.
    mechanism : str, optional
        Its id (default: the first mechanism).

    Raises
    ------
    InputError
        No mechanism of that id (field ``mechanism``; the message lists the ids).
    """
    found = cf.mechanisms[0] if mechanism is None else None
    for mech in cf.mechanisms if mechanism is not None else ():
        if mech.id == mechanism:
            found = mech
    if found is None:
        ids = [m.id for m in cf.mechanisms]
        raise InputError(f"no mechanism {mechanism!r}; the file has {ids}", "mechanism")
    data: dict[str, Any] = json.loads(found.model_dump_json(exclude_none=True))
    return data


def _pulse_request(request: Union[PulseRequest, Mapping[str, Any]]) -> PulseRequest:
    """Validate a mapping as a ``PulseRequest``; an error names the field (as REST's 422)."""
    if isinstance(request, PulseRequest):
        return request
    if not isinstance(request, Mapping):
        example = 'e.g. {"p_eq": 2.2, "lam": 0.165, "eta": 0.96, "a_p_g": -0.3, "f_p": 1.0}'
        raise wrong_type(request, "request", "a PulseRequest or a dict of its fields", example)
    try:
        return PulseRequest.model_validate(dict(request))
    except ValidationError as err:
        raise input_error_from_validation(err) from None


def solve_pulse(request: Union[PulseRequest, Mapping[str, Any]]) -> PulseDocument:
    """Response of one mechanism to a one-cycle pulse: the one function of every front end.

    ``rockmech pulse``, REST ``/pulse``, the Hops pulse component, RM_Analyse and RM_RunPulse
    (run here or on the service) and the Python API all build a ``PulseRequest`` and call
    this, so that the same request gets the same verdict and numbers on every path.

    Parameters
    ----------
    request : PulseRequest or mapping
        The request (a mapping is validated as ``PulseRequest``; an error names the field).
        ``a_p_g`` [g] is signed (> 0 first pushes towards negative rotation), ``f_p`` [Hz].

    Returns
    -------
    PulseDocument
        The document ``rockmech pulse --json`` prints (``to_dict()``): ``input`` (the
        problem as solved, both sides when they differ), the verdict under ``criterion``
        (``exact`` by default), ``t_overturn`` [s] (the time of the collapse the verdict refers to),
        ``peak_ratio`` with its ``error_estimate``, work counters, ``units`` and ``version``.

    Examples
    --------
    >>> doc = solve_pulse({"p_eq": 2.0, "lam": 0.2, "eta": 0.95, "a_p_g": 0.282, "f_p": 0.32})
    >>> doc.overturned, round(doc.t_overturn, 3)
    (True, 3.649)
    """
    request = _pulse_request(request)
    model = pulse_model(request)
    model.require_eta()
    pulse = Pulse.from_g(request.a_p_g, request.f_p, request.shape)
    res = simulate(model, pulse, criterion=request.criterion)
    pos = model.positive
    problem: dict[str, Any] = {
        "p_eq": pos.p_eq,
        "lam": pos.lam,
        "phi_ov": pos.phi_ov,
        "eta": model.eta,
        "rocking": "one_sided" if model.one_sided else "two_sided",
    }
    if request.mechanism is not None:
        problem = {"mechanism": request.mechanism.id, **problem}
        if not model.is_symmetric:
            neg = model.neg
            problem["negative"] = {"p_eq": neg.p_eq, "lam": neg.lam, "phi_ov": neg.phi_ov}
        if model.is_directional:
            problem["eta_to_negative"] = model.eta_into(-1)
            problem["eta_to_positive"] = model.eta_into(1)
    doc = {
        "input": {
            **problem,
            "a_p_g": request.a_p_g,
            "f_p": request.f_p,
            "shape": request.shape,
            "omega_ratio": pulse.omega_p / pos.p_eq,
            "amplitude_ratio": abs(request.a_p_g) / pos.lam,
            "pulse_convention": "A (Zhang & Makris 2001: pulse starts at t = 0)",
        },
        **res.summary(),
    }
    return PulseDocument.model_validate(stamp(doc, "pulse"))
