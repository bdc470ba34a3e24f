"""The IDA document: incremental dynamic analysis over records, with lognormal fragility fits.

``rockmech ida --json`` and ``ida.json``. Per mechanism, the number and fraction of the
records that overturn it at each intensity level, the first level that overturns it per
record and a lognormal fragility fit (binomial maximum likelihood). Units: the levels, the
first overturning levels and the fits' medians are in the intensity measure's units
(``intensity.units``: ``-`` for scale factors, ``g`` for PGA); PGA in g, times in s;
fractions and dispersions dimensionless. Python 3.9-clean.
"""

from typing import List, Literal, Optional

from pydantic import Field

from .base import Document, Part, find_entry
from .history import SkippedMechanism

__all__ = [
    "IdaBackend",
    "IdaDocument",
    "IdaFragility",
    "IdaMechanism",
    "IdaPeaks",
    "IdaRecord",
    "Intensity",
]


class Intensity(Part):
    """The intensity measure and its levels."""

    measure: Literal["scale", "pga"] = Field(
        description="Intensity measure: scale factors on every record, or target PGAs."
    )
    units: str = Field(description="Units of the levels (``-`` for scale, ``g`` for PGA).")
    levels: List[float] = Field(description="The levels, ascending (``units``).")


class IdaRecord(Part):
    """A record of the analysis as read."""

    name: str = Field(description="The record's name.")
    pga_g: Optional[float] = Field(description="Peak ground acceleration, unscaled [g].")
    dt_s: Optional[float] = Field(description="Time step [s].")
    n_samples: int = Field(description="Samples in the record.")


class IdaFragility(Part):
    """A mechanism's lognormal fragility fit, or why there is none.

    ``median``, ``beta`` and ``log_likelihood`` are present together, or absent where the
    levels cannot place the median (every record overturned it at the lowest level, or none
    at the highest).
    """

    method: str = Field(description="How the curve is fitted.")
    median: Optional[float] = Field(
        None, description="Intensity at which half the records overturn (intensity.units)."
    )
    beta: Optional[float] = Field(None, description="Lognormal dispersion [-].")
    log_likelihood: Optional[float] = Field(
        None, description="The maximised binomial log-likelihood [-]."
    )
    note: str = Field(
        "", description="How to read the fit, or why there is none (absent: a sound fit)."
    )


class IdaMechanism(Part):
    """One mechanism over every record and level."""

    id: str = Field(description="The mechanism's id.")
    n_overturned: List[int] = Field(description="Per level, the records that overturn it.")
    fraction: List[float] = Field(
        description="Per level, the fraction of the records that overturn it [-]."
    )
    first_overturning_level: List[Optional[float]] = Field(
        description="Per record, the lowest level that overturns it (intensity.units); null: "
        "none does."
    )
    fragility: IdaFragility = Field(description="The lognormal fit of the fractions.")
    scale_factors: Optional[List[Optional[float]]] = Field(
        None,
        description="With a scale factor up the structure: per record, the mechanism's "
        "factor [-] (null: none applies).",
    )


class IdaBackend(Part):
    """Where the runs ran, and how the work was cut (timings on the workers' clocks)."""

    kind: Literal["local", "dask"] = Field(description="Threads of this process, or Dask.")
    jobs: Optional[int] = Field(None, description="Local: threads of the run.")
    scheduler: Optional[str] = Field(None, description="Dask: the scheduler's address.")
    n_workers: Optional[int] = Field(None, description="Dask: workers of the cluster.")
    threads: Optional[int] = Field(None, description="Dask: worker threads in all.")
    tasks: int = Field(description="Tasks the runs were cut into.")
    settings_differ: Optional[List[str]] = Field(
        None,
        description="Dask: the settings the workers run otherwise than rockmech's, one line each.",
    )
    lanes: int = Field(description="Worker threads that ran tasks.")
    task_s: float = Field(description="Mean task time [s].")
    overhead_per_task_s: float = Field(
        description="Mean time in a task outside the kernels, plus the gap before the next "
        "task on the same worker thread [s]."
    )
    overhead_fraction: float = Field(description="overhead_per_task_s over task_s [-].")
    gap_per_task_s: float = Field(description="The gap alone, per task [s].")
    span_s: float = Field(description="From the first task's start to the last one's end [s].")


class IdaPeaks(Part):
    """The Parquet file of the per-run peaks."""

    file: str = Field(description="The file's name, beside ida.json.")
    rows: int = Field(description="Rows written: records x mechanisms x levels.")


class IdaDocument(Document):
    """Incremental dynamic analysis (``rockmech ida --json``, ``ida.json``)."""

    intensity: Intensity = Field(description="The intensity measure and its levels.")
    records: List[IdaRecord] = Field(description="The records, in the order given.")
    criterion: str = Field(description="The overturning verdict (ratio, exact).")
    method: str = Field(description="The integration method.")
    mechanisms: List[IdaMechanism] = Field(description="One per mechanism, in file order.")
    runs: int = Field(description="Runs: records x mechanisms x levels.")
    max_error_estimate: Optional[float] = Field(
        description="The largest error estimate of a peak ratio over the runs [-]."
    )
    runtime_s: float = Field(description="Wall time of the analysis [s].")
    compute_s: float = Field(description="Time inside the kernels, summed over the tasks [s].")
    backend: IdaBackend = Field(description="Where the runs ran.")
    peaks: Optional[IdaPeaks] = Field(None, description="With --peaks: the per-run peaks.")
    scale_factor_method: Optional[str] = Field(
        None, description="The scale factor up the structure (eq28, ec8, nzs), when used."
    )
    incomplete_runs: Optional[int] = Field(
        None,
        description="Runs the solver stopped short (impact limit, or a state no longer "
        "finite): their verdict is incomplete.",
    )
    skipped: Optional[List[SkippedMechanism]] = Field(
        None, description="Mechanisms left out (no coefficient of restitution)."
    )

    @property
    def measure(self) -> str:
        """The intensity measure, ``"scale"`` [-] or ``"pga"`` [g]."""
        return self.intensity.measure

    @property
    def levels(self) -> List[float]:
        """The intensity levels, ascending, in the measure's units."""
        return self.intensity.levels

    def find(self, mechanism_id: str) -> IdaMechanism:
        """Return the mechanism ``mechanism_id``: its ``fraction`` per level and ``fragility``."""
        return find_entry(self.mechanisms, mechanism_id)
