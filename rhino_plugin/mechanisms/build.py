"""Spec + scene -> kinematic-constants file (single block A1 and loaded wall A2).

The result validates against ``shared_schema.constants`` and carries, per mechanism, a
geometry summary (mass, centre of mass, R, alpha, I_O per side; for loaded walls the
combined quantities and every element) and its provenance (source files, object ids,
options, warnings from mesh repair).
"""

from pathlib import Path
from typing import Any, Dict, List, Optional

import numpy as np

from rhino_plugin.mechanisms import single
from rhino_plugin.mechanisms.loaded import loaded_side
from rhino_plugin.mechanisms.multi_block_cad import multi_block_sides
from rhino_plugin.mechanisms.restitution import ONE_SIDED_RULES, one_sided
from rhino_plugin.mechanisms.thrust import ThrustTable
from rhino_plugin.mechanisms.two_block_cad import two_block_sides
from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError
from shared_schema.rules import eta_range

__all__ = ["constants_from_spec", "mechanism_entry"]

#: Two sides whose constants agree to this relative tolerance are stored once (symmetric).
SYMMETRY_RTOL = 1e-9


def _same(a: Dict[str, float], b: Dict[str, float]) -> bool:
    return all(abs(a[k] - b[k]) <= SYMMETRY_RTOL * max(abs(a[k]), abs(b[k]), 1e-300) for k in a)


def mechanism_entry(spec: Any, scene: Any, table: Any) -> Dict[str, Any]:
    """One mechanism of the constants file from its spec."""
    where = spec.id
    entry: Dict[str, Any] = {
        "id": spec.id,
        "name": spec.name or spec.id,
        "typology": spec.typology,
        "rocking": spec.rocking,
    }
    if spec.typology == "multi_block":
        positive, negative, eta, summary, ids = multi_block_sides(spec, scene)
        warnings = summary.pop("warnings")
        return _finish(
            spec,
            entry,
            {"multi_block": summary},
            positive,
            negative,
            eta,
            "momentum_projection",
            {},
            ids,
            warnings,
        )
    start, end = single.resolve_axis(scene, spec.axis, f"{where}.axis")
    body = single.load_body(spec, scene, 0.5 * (start + end))
    pos = single.rocking_side(
        body, start, end, where=f"{where}.axis", allow_tilt=spec.allow_non_horizontal_axis
    )
    geometry: Dict[str, Any] = {
        "mass_kg": float(body.props.mass),
        "volume_m3": float(sum(p.volume for p in body.parts)),
        "com_m": [float(v) for v in body.props.com],
        "positive": single.side_summary(pos),
    }
    warnings = list(body.warnings)
    if spec.typology == "two_block":
        positive, negative, eta, summary = two_block_sides(spec, scene, body, pos)
        geometry["two_block"] = summary
        return _finish(
            spec,
            entry,
            geometry,
            positive,
            negative,
            eta,
            "momentum_projection",
            {},
            body.object_ids,
            warnings,
        )
    if spec.typology == "single_block_loaded":
        if spec.rocking == "two_sided":
            raise InputError(
                "two-sided rocking of a loaded wall is not supported (added forces act on one "
                "side); use one_sided",
                f"{where}.rocking",
            )
        positive, loaded_summary, notes = loaded_side(spec, scene, body, pos, table)
        warnings.extend(notes)
        geometry["loaded"] = loaded_summary
        m_eta = loaded_summary["M_c_kg"]
        r_eta, a_eta, i_eta = loaded_summary["R_c_m"], loaded_summary["alpha_c_rad"], positive["I0"]
    else:
        positive = single.side_constants(body, pos)
        m_eta, r_eta, a_eta, i_eta = float(body.props.mass), pos.R, pos.alpha, pos.I_O
    negative = None
    eta_info: Dict[str, Any]
    if spec.rocking == "two_sided":
        if spec.axis_negative is not None:
            n_start, n_end = single.resolve_axis(
                scene, spec.axis_negative, f"{where}.axis_negative"
            )
        else:
            n_start, n_end = single.negative_axis(body, pos)
        neg = single.rocking_side(
            body,
            n_start,
            n_end,
            where=f"{where}.axis_negative",
            allow_tilt=spec.allow_non_horizontal_axis,
        )
        if float(np.dot(neg.outward, pos.outward)) >= 0.0:
            raise InputError(
                "the negative-side axis must lie on the other side of the centre of mass",
                f"{where}.axis_negative",
            )
        negative = single.side_constants(body, neg)
        geometry["negative"] = single.side_summary(neg)
        eta, eta_info = single.eta_two_sided(body, pos, neg)
        source = "housner_general"
    else:
        source = spec.eta_rule or "one_sided_eq26"
        eta = one_sided(m_eta, r_eta, a_eta, i_eta, source)
        eta_info = {"rule": ONE_SIDED_RULES[source]}
    return _finish(
        spec, entry, geometry, positive, negative, eta, source, eta_info, body.object_ids, warnings
    )


def _finish(
    spec: Any,
    entry: Dict[str, Any],
    geometry: Dict[str, Any],
    positive: Dict[str, float],
    negative: Optional[Dict[str, float]],
    eta: Optional[float],
    source: str,
    eta_info: Dict[str, Any],
    ids: List[str],
    warnings: List[str],
) -> Dict[str, Any]:
    """Complete an entry: sides, restitution, amplification, geometry and provenance.

    The negative side is stored only where it differs from the positive one. A computed
    ``eta`` outside the range of the rocking kind ([0, 1] two-sided, [-1, 0] one-sided; a
    very stocky body) is clamped with a warning; a user ``eta`` overrides it, and the
    computed value is kept in the geometry summary.
    """
    entry["positive"] = positive
    if negative is not None and not _same(positive, negative):
        entry["negative"] = negative
    if eta is not None:
        lo, hi = eta_range(spec.rocking == "one_sided")
        if not lo <= eta <= hi:
            clamped = min(max(eta, lo), hi)
            warnings.append(
                f"{spec.id}: {source} gives eta = {eta:.4f}, outside [{lo:g}, {hi:g}] for "
                f"{spec.rocking} rocking (a very stocky body); eta set to {clamped:g}"
            )
            eta = clamped
    if spec.eta is not None:
        entry["eta"], entry["eta_source"] = spec.eta, "user"
        if eta is not None:
            eta_info["computed"] = eta
    elif eta is not None:
        entry["eta"], entry["eta_source"] = eta, source
    if eta_info:
        geometry["restitution"] = eta_info
    if spec.amplification is not None:
        entry["amplification"] = spec.amplification.model_dump()
    entry["geometry"] = geometry
    entry["provenance"] = {"object_ids": ids, "warnings": warnings}
    return entry


def constants_from_spec(
    spec_file: Any,
    scene: Any,
    *,
    scene_name: str,
    spec_name: str,
    spec_dir: Optional[Path] = None,
) -> ConstantsFile:
    """Kinematic-constants file for every mechanism of a spec file."""
    table_path = None
    if spec_file.thrust_table is not None:
        table_path = Path(spec_file.thrust_table)
        if not table_path.is_absolute() and spec_dir is not None:
            table_path = spec_dir / table_path
    table = ThrustTable.load(table_path)
    mechanisms: List[Dict[str, Any]] = []
    for spec in spec_file.mechanisms:
        entry = mechanism_entry(spec, scene, table)
        entry["provenance"].update(
            {
                "scene": scene_name,
                "spec": spec_name,
                "scene_units": scene.units,
                "thrust_table": table.name if spec.vaults else None,
            }
        )
        if entry["provenance"]["thrust_table"] is None:
            del entry["provenance"]["thrust_table"]
        mechanisms.append(entry)
    return ConstantsFile.model_validate({"mechanisms": mechanisms})
