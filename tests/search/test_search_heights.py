"""Each mechanism ranked where it sits (issue #37).

A three-storey façade (``search_scenes.three_storey_facade``): the partial overturning of
its top storey sits at Z = 7 m. With the building's first mode (the search spec's
``first_mode``, or the site's ``building``) its envelope is the ground-level one divided by
Eq. 28's pulse scale factor ``SF(f_p) = sqrt(1 + (R(f_p/f_n) Z/h_e)²)`` (theory §7.3), with
R the 5 % pulse response spectrum of §7.1, computed here by integrating the oscillator
(scipy's DOP853), independently of the product's closed form. At a_g = 0.15 g the top
storey's mechanisms pass the linear code check on the ground's spectrum and fail on the
floor spectrum at Z ([C7.2.7], computed here by hand); without building data their check
is incomplete and the document says the ranking is at ground level.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from search_scenes import three_storey_facade, three_storey_spec, write_spec

from cad_maths.scenes import read_scene
from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError
from shared_schema.search import SearchSpec
from solver_service.workflows.assess import read_site
from solver_service.workflows.codecheck import check_doc
from solver_service.workflows.search import search_from_files, search_run

F_N, H_E = 4.0, 8.0
BAND = {"band_hz": [1.0, 8.0], "n_frequencies": 8}
A_G, F0, TC = 0.15, 2.4, 0.3
H_BLD, STOREYS = 10.5, 3


def pulse_spectrum(r: float, zeta: float = 0.05) -> float:
    """Peak ``ω_n² max|u| / a_p`` of an oscillator at rest under one sine-pulse cycle."""

    def rhs(t: float, y: np.ndarray, forced: bool) -> list[float]:
        load = -math.sin(r * t) if forced else 0.0
        return [y[1], load - 2.0 * zeta * y[1] - y[0]]

    t_p = 2.0 * math.pi / r
    opts = {"method": "DOP853", "rtol": 1e-11, "atol": 1e-13, "dense_output": True}
    one = solve_ivp(rhs, (0.0, t_p), [0.0, 0.0], args=(True,), **opts)
    two = solve_ivp(rhs, (t_p, t_p + 12 * math.pi), one.y[:, -1], args=(False,), **opts)
    peak = 0.0
    for sol, (a, b) in ((one, (0.0, t_p)), (two, (t_p, t_p + 12 * math.pi))):
        t = np.linspace(a, b, 40_000)
        peak = max(peak, float(np.abs(sol.sol(t)[0]).max()))
    return peak


@pytest.fixture(scope="module")
def scene(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return three_storey_facade(tmp_path_factory.mktemp("storeys"))


def _site(tmp: Path, building: bool = True, **hazard: Any) -> Path:
    doc: dict[str, Any] = {
        "schema_version": "1.0",
        "hazard": {
            "code": "NTC2018",
            "a_g": A_G,
            "F0": F0,
            "Tc_star": TC,
            "soil": "A",
            "topography": "T1",
            "limit_state": "SLV",
            "FC": 1.0,
            "q": 2.0,
            **hazard,
        },
    }
    if building:
        doc["building"] = {"height": H_BLD, "storeys": STOREYS}
    path = tmp / ("site.json" if building else "site_no_building.json")
    path.write_text(json.dumps(doc))
    return path


def _by_place(doc: dict[str, Any]) -> dict[tuple[str, float], dict[str, Any]]:
    return {(c["family"], round(c["Z_m"], 9)): c for c in doc["candidates"]}


def test_the_top_storey_is_ranked_on_the_amplified_envelope_of_eq28(scene: Path) -> None:
    ground = search_run(
        read_scene(scene), SearchSpec.model_validate(three_storey_spec(ranking=BAND))
    )
    spec = three_storey_spec(ranking=BAND, first_mode={"f_n": F_N, "h_e": H_E})
    run = search_run(read_scene(scene), SearchSpec.model_validate(spec))
    assert ground.doc.to_dict()["building"]["given"] is False
    assert "no building data" in ground.doc.to_dict()["assumptions"][-1]
    info = run.doc.to_dict()["building"]
    assert info["given"] and info["f_n_hz"] == F_N and info["h_e_m"] == H_E
    assert info["T1_source"].startswith("search spec first_mode.f_n")
    assert info["h_e_source"] == "search spec first_mode.h_e"
    f_p = np.asarray(run.doc.to_dict()["band"]["f_p"])
    before, after = _by_place(ground.doc.to_dict()), _by_place(run.doc.to_dict())
    top = after[("partial_overturning", 7.0)]
    assert top["amplification"] == {"f_n": F_N, "h_e": H_E, "h": 7.0}
    sf = np.array([math.hypot(1.0, pulse_spectrum(f / F_N) * 7.0 / H_E) for f in f_p])
    local = np.asarray(before[("partial_overturning", 7.0)]["overturning"]["a_p_min_g"])
    amplified = np.asarray(top["overturning"]["a_p_min_g"])
    # the library's tabulated spectrum is within 1e-4 of the exact one
    assert amplified == pytest.approx(local / sf, rel=3e-4)
    assert top["overturning"]["a_p_min_local_g"] == pytest.approx(list(local), rel=1e-12)
    ratio = (
        before[("partial_overturning", 7.0)]["overturning"]["band_score_g"]
        / (top["overturning"]["band_score_g"])
    )
    assert ratio > 1.5  # ranked at ground level it looked this much safer
    # at ground level nothing changes and no amplification is written
    base = after[("overturning", 0.0)]
    assert "amplification" not in base
    assert base["overturning"] == before[("overturning", 0.0)]["overturning"]
    # the mechanism spec carries it, for `rockmech constants` and `check` to reopen
    assert run.spec_file is not None
    amps = {m.id: m.amplification for m in run.spec_file.mechanisms}
    assert amps[base["id"]] is None and amps[top["id"]].h == 7.0
    # and the dynamic ranking moved the top storey up
    assert top["rank_dynamic"] < before[("partial_overturning", 7.0)]["rank_dynamic"]


def test_at_ag_015_the_top_storey_passes_on_the_ground_and_fails_at_its_height(
    scene: Path, tmp_path: Path
) -> None:
    site = _site(tmp_path)
    run = search_run(
        read_scene(scene),
        SearchSpec.model_validate(three_storey_spec(ranking=BAND)),
        site=read_site(site),
    )
    info = run.doc.to_dict()["building"]
    t1 = 0.05 * H_BLD**0.75  # Circ. 2019 [C7.3.2]
    assert info["T1_s"] == pytest.approx(t1, rel=1e-12)
    assert info["h_e_m"] == pytest.approx(H_BLD * (2 * STOREYS + 1) / (3 * STOREYS), rel=1e-12)
    assert 0.1 <= t1 < TC  # the plateau of the soil-A spectrum: S_e(T1) = a_g F0
    gamma = 3 * STOREYS / (2 * STOREYS + 1)  # [C7.2.10]
    assert run.constants is not None
    bare = ConstantsFile(
        mechanisms=[m.model_copy(update={"amplification": None}) for m in run.constants.mechanisms]
    )
    on_ground = {r["id"]: r for r in check_doc(bare, read_site(site))["mechanisms"]}
    failed = []
    for z in (7.0, 7.2):
        d = _by_place(run.doc.to_dict())[("partial_overturning", z)]
        lin = d["code_check"]["linear"]
        a_z = A_G * F0 * gamma * (z / H_BLD) * math.sqrt(1.0 + 0.0004 * 5.0**2)  # [C7.2.7]
        assert lin["capacity_ratio"] == pytest.approx(
            2.0 * lin["a0_star"] / (a_z * 9.80665), rel=1e-9
        )
        assert lin["capacity_ratio"] < 1.0 and d["code_check"]["passes"] is False
        g = on_ground[d["id"]]["linear"]
        assert g["capacity_ratio"] == pytest.approx(2.0 * g["a0_star"] / (A_G * 9.80665), rel=1e-9)
        assert g["capacity_ratio"] >= 1.0 and g["passes"] is True
        failed.append(d["id"])
    assert len(failed) == 2


def test_without_building_data_a_mechanism_above_ground_is_incomplete(
    scene: Path, tmp_path: Path
) -> None:
    site = _site(tmp_path, building=False)
    run = search_run(
        read_scene(scene),
        SearchSpec.model_validate(three_storey_spec(ranking=BAND)),
        site=read_site(site),
    )
    assert not run.doc.to_dict()["building"]["given"]
    assert any("no building data" in n for n in run.doc.to_dict()["notes"])
    top = _by_place(run.doc.to_dict())[("partial_overturning", 7.0)]
    check = top["code_check"]
    assert check["Z"] == 7.0 and check["passes"] is None
    assert "gives no building" in check["linear"]["note"]
    base = _by_place(run.doc.to_dict())[("overturning", 0.0)]["code_check"]
    assert base["Z"] == 0.0 and base["passes"] is not None


def test_a_first_mode_that_contradicts_the_sites_period_is_refused_before_the_search(
    scene: Path, tmp_path: Path
) -> None:
    doc = json.loads(_site(tmp_path).read_text())
    doc["building"]["T1"] = 0.3
    (tmp_path / "site.json").write_text(json.dumps(doc))
    spec = write_spec(
        tmp_path / "s.json",
        three_storey_spec(
            ranking={**BAND, "site": "site.json"}, first_mode={"f_n": 2.0, "h_e": H_E}
        ),
    )
    with pytest.raises(InputError) as err:
        search_from_files(scene, spec)
    assert err.value.field == "first_mode.f_n" and "building.T1 = 0.3 s" in str(err.value)


def test_records_are_scaled_up_to_the_mechanisms_height(scene: Path, tmp_path: Path) -> None:
    record = Path(__file__).resolve().parents[2] / "examples" / "records" / "elcentro_NS.dat"
    spec = three_storey_spec(
        ranking={**BAND, "records": [str(record)], "keep": 2}, first_mode={"f_n": F_N, "h_e": H_E}
    )
    run = search_run(read_scene(scene), SearchSpec.model_validate(spec))
    seen = 0
    for d in run.doc.to_dict()["candidates"]:
        for rec in d.get("records", []):
            if d["Z_m"] == 0.0:
                assert "scale_factor" not in rec
                continue
            info = rec["scale_factor"]
            inputs = info["inputs"]
            assert info["value"] == pytest.approx(
                math.hypot(1.0, inputs["sa_g"] / inputs["pga_g"] * d["Z_m"] / H_E), rel=1e-12
            )
            if rec["scale_local"] is not None:
                assert rec["scale"] * info["value"] == pytest.approx(rec["scale_local"], rel=1e-12)
            seen += 1
    assert seen >= 1


def test_a_tie_at_the_top_storey_raises_every_mechanism_it_crosses(
    scene: Path, tmp_path: Path
) -> None:
    """The three-storey façade with a 30 kN tie-bar at 9 m (a line through its outer face):
    the tie does work F (z_t − z_h) per unit rotation of every mechanism whose hinge lies
    below it, none above. Reference (virtual work per unit rotation about the hinge at z_h,
    written here): λ0 = [W t/2 + F (z_t − z_h)⁺ / g] / [W (h − z_h)/2 + Σ m_f (z_f − z_h)]
    with W the façade's mass above z_h and m_f the floors' shares (tributary 0.5, abutting:
    inertia only) at their contact's centroid z_f above z_h. The LP check holds the best."""
    import rhino3dm as r3

    from solver_service.core.model import G

    f3dm = r3.File3dm.Read(str(scene))
    attrs = r3.ObjectAttributes()
    attrs.Name = "tie"
    f3dm.Objects.AddLine(r3.Point3d(-0.2, 4.0, 9.0), r3.Point3d(6.5, 4.0, 9.0), attrs)
    tied = tmp_path / "tied.3dm"
    assert f3dm.Write(str(tied), 7)
    force, z_t = 30000.0, 9.0
    spec = three_storey_spec(tie_bars=[{"object": "tie", "force": force}], lp=True)
    doc = search_from_files(tied, write_spec(tmp_path / "tied.json", spec)).doc.to_dict()
    t, length, h = 0.5, 8.0, 10.5
    m_f = 0.5 * 2400.0 * 6.0 * (8.0 - 2 * 0.45 - 0.02) * 0.2
    floors = (3.6, 7.1, 10.4)  # the 0.2 m floors abutting from 3.5, 7.0 and 10.3 m
    assert {c["family"] for c in doc["candidates"]} == {"overturning", "partial_overturning"}
    for c in doc["candidates"]:
        z_h = c["parameters"]["hinge_height_m"]
        w = 1800.0 * t * length * (h - z_h)
        num = w * t / 2.0 + force * max(z_t - z_h, 0.0) / G
        den = w * (h - z_h) / 2.0 + sum(m_f * (z - z_h) for z in floors if z > z_h)
        assert c["lam0"] == pytest.approx(num / den, rel=1e-9), z_h
        assert bool(c["tie_bars"]) is (z_t > z_h)
    hinges = sorted(c["parameters"]["hinge_height_m"] for c in doc["candidates"])
    assert hinges == [0.0, 3.5, 3.7, 7.0, 7.2, 10.3]
    (lp,) = doc["lp"]
    assert lp["status"] == "optimal" and lp["missed"] is False
    assert lp["lam"] <= lp["best_catalogue_lam0"] * (1.0 + 1e-9)
