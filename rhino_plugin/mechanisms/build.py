"""Spec + scene -> kinematic-constants file (single block A1 and loaded wall A2).

The result validates against ``shared_schema.constants`` and carries, per mechanism, a
geometry summary (mass, centre of mass, R, alpha, I_O per side; for loaded walls the
combined quantities and every element) and its provenance (source files, object ids,
options, warnings from mesh repair).
"""

from pathlib import Path
from typing import Any, Dict, List, Optional

import numpy as np

from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError

__all__ = ["constants_from_spec", "mechanism_entry"]

#: Two sides whose constants agree to this relative tolerance are stored once (symmetric).
SYMMETRY_RTOL = 1e-9


def _same(a: Dict[str, float], b: Dict[str, float]) -> bool:
    return all(abs(a[k] - b[k]) <= SYMMETRY_RTOL * max(abs(a[k]), abs(b[k]), 1e-300) for k in a)


def mechanism_entry(spec: Any, scene: Any, table: Any) -> Dict[str, Any]:
    """One mechanism of the constants file from its spec."""
    from rhino_plugin.mechanisms import single
    from rhino_plugin.mechanisms.loaded import loaded_side
    from rhino_plugin.mechanisms.restitution import ONE_SIDED_RULES, one_sided

    where = spec.id
    if spec.typology == "multi_block":
        return _multi_block_entry(spec, scene)
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
    entry: Dict[str, Any] = {
        "id": spec.id,
        "name": spec.name or spec.id,
        "typology": spec.typology,
        "rocking": spec.rocking,
    }
    warnings = list(body.warnings)
    if spec.typology == "two_block":
        return _two_block_entry(spec, scene, body, pos, entry, geometry, warnings)
    if spec.typology == "single_block_loaded":
        if spec.rocking == "two_sided":
            raise InputError(
                "two-sided rocking of a loaded wall is not supported (added forces act on one "
                "side); use one_sided",
                f"{where}.rocking",
            )
        consts, loaded_summary, notes = loaded_side(spec, scene, body, pos, table)
        warnings.extend(notes)
        geometry["loaded"] = loaded_summary
        m_eta = loaded_summary["M_c_kg"]
        r_eta, a_eta, i_eta = loaded_summary["R_c_m"], loaded_summary["alpha_c_rad"], consts["I0"]
        entry["positive"] = consts
    else:
        consts = single.side_constants(body, pos)
        entry["positive"] = consts
        m_eta, r_eta, a_eta, i_eta = float(body.props.mass), pos.R, pos.alpha, pos.I_O
    eta_info: Dict[str, Any] = {}
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
        neg_consts = single.side_constants(body, neg)
        geometry["negative"] = single.side_summary(neg)
        if not _same(consts, neg_consts):
            entry["negative"] = neg_consts
        eta, eta_info = single.eta_two_sided(body, pos, neg)
        source = "housner_general"
        if eta < 0.0:
            warnings.append(
                f"{where}: Housner's rule gives eta = {eta:.4f} < 0 (a very stocky body); "
                "eta set to 0"
            )
            eta = 0.0
    else:
        rule = spec.eta_rule or "one_sided_eq26"
        eta = one_sided(m_eta, r_eta, a_eta, i_eta, rule)
        eta_info = {"rule": ONE_SIDED_RULES[rule]}
        source = rule
        if eta > 0.0:
            warnings.append(
                f"{where}: {rule} gives eta = {eta:.4f} > 0 (a stocky body does not rebound); "
                "eta set to 0"
            )
            eta = 0.0
    if spec.eta is not None:
        entry["eta"], entry["eta_source"] = spec.eta, "user"
        eta_info["computed"] = eta
    else:
        entry["eta"], entry["eta_source"] = eta, source
    if spec.amplification is not None:
        entry["amplification"] = spec.amplification.model_dump()
    geometry["restitution"] = eta_info
    entry["geometry"] = geometry
    entry["provenance"] = {"object_ids": body.object_ids, "warnings": warnings}
    return entry


def _two_block_entry(
    spec: Any,
    scene: Any,
    body: Any,
    pos: Any,
    entry: Dict[str, Any],
    geometry: Dict[str, Any],
    warnings: List[str],
) -> Dict[str, Any]:
    """Fill in a two-block wall's entry (A3; see ``two_block_cad``)."""
    from rhino_plugin.mechanisms.two_block_cad import two_block_sides

    positive, negative, eta, summary = two_block_sides(spec, scene, body, pos)
    entry["positive"] = positive
    if negative is not None and not _same(positive, negative):
        entry["negative"] = negative
    geometry["two_block"] = summary
    if spec.eta is not None:
        entry["eta"], entry["eta_source"] = spec.eta, "user"
        if eta is not None:
            geometry["restitution"] = {"computed": eta}
    elif eta is not None:
        if eta < 0.0:
            warnings.append(
                f"{spec.id}: the momentum projection gives eta = {eta:.4f} < 0; eta set to 0"
            )
            eta = 0.0
        entry["eta"], entry["eta_source"] = eta, "momentum_projection"
    if spec.amplification is not None:
        entry["amplification"] = spec.amplification.model_dump()
    entry["geometry"] = geometry
    entry["provenance"] = {"object_ids": body.object_ids, "warnings": warnings}
    return entry


def _multi_block_entry(spec: Any, scene: Any) -> Dict[str, Any]:
    """Fill in a three-block, four-hinge mechanism's entry (A4; see ``multi_block_cad``)."""
    from rhino_plugin.mechanisms.multi_block_cad import multi_block_sides

    positive, negative, eta, summary, ids = multi_block_sides(spec, scene)
    warnings = summary.pop("warnings")
    entry: Dict[str, Any] = {
        "id": spec.id,
        "name": spec.name or spec.id,
        "typology": spec.typology,
        "rocking": spec.rocking,
        "positive": positive,
    }
    if negative is not None and not _same(positive, negative):
        entry["negative"] = negative
    if spec.eta is not None:
        entry["eta"], entry["eta_source"] = spec.eta, "user"
    elif eta is not None:
        if eta < 0.0:
            warnings.append(
                f"{spec.id}: the momentum projection gives eta = {eta:.4f} < 0; eta set to 0"
            )
            eta = 0.0
        entry["eta"], entry["eta_source"] = eta, "momentum_projection"
    if spec.amplification is not None:
        entry["amplification"] = spec.amplification.model_dump()
    entry["geometry"] = {"multi_block": summary}
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
    from rhino_plugin.mechanisms.thrust import ThrustTable

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
