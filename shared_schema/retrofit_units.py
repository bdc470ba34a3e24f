"""The units of the retrofit document (``rockmech retrofit``), apart from its models.

``shared_schema.retrofit`` fills the document's ``units`` from here and re-exports the
name; ``solver_service.workflows.units`` puts it beside the other documents' units without
loading the retrofit's models (a pulse loads no retrofit, #38). Python 3.9-clean.
"""

from typing import Dict

__all__ = ["RETROFIT_UNITS"]

#: The units of the retrofit document's quantities whose names do not state them (a name
#: ending in ``_N``, ``_m``, ``_mm``, ``_kg`` states its own; ``-`` is dimensionless): the
#: ``units`` block every rockmech document carries (``solver_service.workflows.units``).
RETROFIT_UNITS: Dict[str, str] = {
    "T_linear_N": "N",
    "T_nonlinear_SLV_N": "N",
    "T_nonlinear_SLC_N": "N",
    "T_star_N": "N",
    "capacity_N": "N",
    "force_N": "N",
    "N_pl_Rd_N": "N",
    "height_m": "m",
    "length_m": "m",
    "diameter_mm": "mm",
    "diameters_mm": "mm",
    "area_mm2": "mm2",
    "f_yk": "N/mm2",
    "f_tk": "N/mm2",
    "gamma_M0": "-",
    "utilisation": "-",
    "steel_mass_kg": "kg",
    "steel_mass_per_m_kg": "kg/m",
    "density_kg_m3": "kg/m3",
    "linear_ratio": "-",
    "SLV_ratio": "-",
    "SLC_ratio": "-",
    "alpha0": "-",
    "e_star": "-",
    "before_margin": "-",
    "after_margin": "-",
    "lam0": "-",
    "after_lam0": "-",
    "least_lam0_value": "-",
    "margin": "-",
    "at_m": "m",
    "end_m": "m",
}
