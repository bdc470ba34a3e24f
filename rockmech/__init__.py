"""rockmech: rocking collapse mechanisms of masonry, from CAD solids to exact rocking responses.

The stable Python API in one place. The code lives in four packages: ``shared_schema``
(file formats and errors), ``cad_maths`` (scene readers, geometry, mechanisms, the search),
``solver_service`` (the solver, workflows, command line and service) and ``rhino_plugin``
(what runs inside Rhino); this package re-exports what scripts need. Importing it is cheap:
each name is imported on first use, so ``import rockmech`` loads neither numpy, scipy,
matplotlib nor rhino3dm.

Examples
--------
>>> import rockmech
>>> wall = rockmech.RockingModel.symmetric(p_eq=2.2, lam=0.165, eta=0.96, name="W2")
>>> res = rockmech.simulate(wall, rockmech.Pulse(a_p=-3.0, f_p=1.0))  # a_p [m/s²], f_p [Hz]
>>> bool(res.overturned), res.peak_ratio
(True, 1.0)
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from rockmech._version import __version__

if TYPE_CHECKING:  # the real types for type checkers and editors
    from cad_maths.scenes import read_scene as read_scene
    from shared_schema.constants import ConstantsFile as ConstantsFile
    from shared_schema.documents.assess import AssessDocument as AssessDocument
    from shared_schema.documents.boundary import BoundaryDocument as BoundaryDocument
    from shared_schema.documents.check import CheckDocument as CheckDocument
    from shared_schema.documents.check import CheckMechanism as CheckMechanism
    from shared_schema.documents.envelope import Band as Band
    from shared_schema.documents.envelope import EnvelopeDocument as EnvelopeDocument
    from shared_schema.documents.history import HistoryDocument as HistoryDocument
    from shared_schema.documents.history import HistoryRow as HistoryRow
    from shared_schema.documents.ida import IdaDocument as IdaDocument
    from shared_schema.documents.ida import IdaMechanism as IdaMechanism
    from shared_schema.documents.pulse import PulseDocument as PulseDocument
    from shared_schema.documents.record import RecordDocument as RecordDocument
    from shared_schema.documents.search import SearchCandidate as SearchCandidate
    from shared_schema.documents.search import SearchDocument as SearchDocument
    from shared_schema.errors import (
        GeometryError as GeometryError,
    )
    from shared_schema.errors import (
        InputError as InputError,
    )
    from shared_schema.errors import (
        RockmechError as RockmechError,
    )
    from shared_schema.errors import (
        SolverError as SolverError,
    )
    from shared_schema.extras import MissingExtra as MissingExtra
    from shared_schema.io import write_constants as write_constants
    from shared_schema.pulse_request import PulseRequest as PulseRequest
    from shared_schema.retrofit import RetrofitDoc as RetrofitDoc
    from shared_schema.retrofit import RetrofitSpec as RetrofitSpec
    from shared_schema.retrofit import read_retrofit_spec as read_retrofit_spec
    from shared_schema.site import SiteFile as SiteFile
    from solver_service.core.envelope import (
        critical_bands as critical_bands,
    )
    from solver_service.core.envelope import (
        mechanism_envelope as mechanism_envelope,
    )
    from solver_service.core.exact import BatchResult as BatchResult
    from solver_service.core.exact import simulate as simulate
    from solver_service.core.exact import simulate_batch as simulate_batch
    from solver_service.core.excitation import Pulse as Pulse
    from solver_service.core.excitation import SampledAccel as SampledAccel
    from solver_service.core.jit import KernelStatus as KernelStatus
    from solver_service.core.jit import kernel_status as kernel_status
    from solver_service.core.model import G as G
    from solver_service.core.model import RockingModel as RockingModel
    from solver_service.core.pulses import (
        extract_pulses as extract_pulses,
    )
    from solver_service.core.pulses import (
        largest_pulse as largest_pulse,
    )
    from solver_service.core.records import GroundMotion as GroundMotion
    from solver_service.core.result import RockingResult as RockingResult
    from solver_service.core.spectra import response_spectrum as response_spectrum
    from solver_service.demo import copy_examples as copy_examples
    from solver_service.demo import examples_dir as examples_dir
    from solver_service.report.html import (
        write_report as write_report,
    )
    from solver_service.workflows.documents import solve_pulse as solve_pulse
    from solver_service.workflows.pages import (
        build_report as build_report,
    )
    from solver_service.workflows.search import SearchRun as SearchRun
    from solver_service.workflows.search import read_search_spec as read_search_spec
    from solver_service.workflows.search import write_search as write_search

    from .analysis import (
        assess as assess,
    )
    from .analysis import (
        check as check,
    )
    from .analysis import (
        constants_from_scene as constants_from_scene,
    )
    from .analysis import (
        envelope as envelope,
    )
    from .analysis import (
        history as history,
    )
    from .analysis import (
        ida as ida,
    )
    from .analysis import (
        models_from_constants as models_from_constants,
    )
    from .analysis import (
        pulse as pulse,
    )
    from .analysis import (
        read_constants as read_constants,
    )
    from .analysis import (
        read_record as read_record,
    )
    from .analysis import (
        read_site as read_site,
    )
    from .analysis import (
        retrofit as retrofit,
    )
    from .analysis import (
        search as search,
    )

#: Each public name and the module it comes from (imported on first access).
_SOURCES = {
    # Errors: every error rockmech raises on purpose is a RockmechError.
    "RockmechError": "shared_schema.errors",
    "InputError": "shared_schema.errors",
    "GeometryError": "shared_schema.errors",
    "SolverError": "shared_schema.errors",
    "MissingExtra": "shared_schema.extras",
    # The kinematic-constants file: read_* reads a file, write_* writes one, the object
    # first and the path second (#38).
    "ConstantsFile": "shared_schema.constants",
    "read_constants": "rockmech.analysis",
    "write_constants": "shared_schema.io",
    # Constants from a scene, the solver's models from constants; records, sites.
    "constants_from_scene": "rockmech.analysis",
    "models_from_constants": "rockmech.analysis",
    "read_record": "rockmech.analysis",
    "read_site": "rockmech.analysis",
    "SiteFile": "shared_schema.site",
    # The analyses, as the command line runs them, and their typed results.
    "pulse": "rockmech.analysis",
    "history": "rockmech.analysis",
    "envelope": "rockmech.analysis",
    "ida": "rockmech.analysis",
    "check": "rockmech.analysis",
    "assess": "rockmech.analysis",
    "retrofit": "rockmech.analysis",
    "RetrofitSpec": "shared_schema.retrofit",
    "RetrofitDoc": "shared_schema.retrofit",
    "read_retrofit_spec": "shared_schema.retrofit",
    "RockingResult": "solver_service.core.result",
    "BatchResult": "solver_service.core.exact",
    "HistoryDocument": "shared_schema.documents.history",
    "HistoryRow": "shared_schema.documents.history",
    "RecordDocument": "shared_schema.documents.record",
    "EnvelopeDocument": "shared_schema.documents.envelope",
    "Band": "shared_schema.documents.envelope",
    "IdaDocument": "shared_schema.documents.ida",
    "IdaMechanism": "shared_schema.documents.ida",
    "CheckDocument": "shared_schema.documents.check",
    "CheckMechanism": "shared_schema.documents.check",
    "AssessDocument": "shared_schema.documents.assess",
    # Models, excitations and the exact solver.
    "G": "solver_service.core.model",
    "RockingModel": "solver_service.core.model",
    "Pulse": "solver_service.core.excitation",
    "SampledAccel": "solver_service.core.excitation",
    "GroundMotion": "solver_service.core.records",
    "simulate": "solver_service.core.exact",
    "simulate_batch": "solver_service.core.exact",
    # One pulse request, one function: the same verdict as the CLI, REST, Hops and Rhino.
    "PulseRequest": "shared_schema.pulse_request",
    "PulseDocument": "shared_schema.documents.pulse",
    "BoundaryDocument": "shared_schema.documents.boundary",
    "solve_pulse": "solver_service.workflows.documents",
    # Envelopes, pulses in records, spectra.
    "mechanism_envelope": "solver_service.core.envelope",
    "critical_bands": "solver_service.core.envelope",
    "extract_pulses": "solver_service.core.pulses",
    "largest_pulse": "solver_service.core.pulses",
    "response_spectrum": "solver_service.core.spectra",
    # The automatic search of a façade's mechanisms (issue #31).
    "search": "rockmech.analysis",
    "SearchRun": "solver_service.workflows.search",
    "SearchDocument": "shared_schema.documents.search",
    "SearchCandidate": "shared_schema.documents.search",
    "write_search": "solver_service.workflows.search",
    "read_search_spec": "solver_service.workflows.search",
    "read_scene": "cad_maths.scenes",
    # Reports and the bundled examples.
    "build_report": "solver_service.workflows.pages",
    "write_report": "solver_service.report.html",
    "examples_dir": "solver_service.demo",
    "copy_examples": "solver_service.demo",
    # Whether the solver's compiled kernels are active (numba) and built.
    "kernel_status": "solver_service.core.jit",
    "KernelStatus": "solver_service.core.jit",
}

__all__ = ["__version__", *_SOURCES]


def __getattr__(name: str) -> Any:
    """Import a public name on first access (PEP 562)."""
    source = _SOURCES.get(name)
    if source is None:
        raise AttributeError(f"module 'rockmech' has no attribute {name!r}")
    value = getattr(importlib.import_module(source), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SOURCES))
