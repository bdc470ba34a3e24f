"""Both impact directions' restitution are stored for asymmetric two-sided mechanisms.

#14: only one eta was stored, though an asymmetric frame's two impact directions differ.
References: Housner's general rule worked by hand for an eccentric column (theory §3.1), and
an independent Newton impact of three rigid bodies with plastic impulses at the new hinges
for a frame with unequal columns (theory §3.4 says the two agree).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
from cad_scenes import BUILD

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scene_3dm import Scene
from shared_schema.constants import parse_constants
from shared_schema.errors import InputError
from shared_schema.spec import parse_spec
from solver_service.core.model import RockingModel, RockingSide
from solver_service.workflows.adapter import to_rocking_model


def scene_of(tmp_path: Path, fill: Callable[[Any], None]) -> Scene:
    b = BUILD.Builder("test")
    fill(b)
    return Scene.from_3dm(b.write(tmp_path / "scene.3dm"))


def run(scene: Scene, mech: dict[str, Any]) -> dict[str, Any]:
    parsed = parse_spec(json.dumps({"mechanisms": [mech]}), "spec.json")
    cf = constants_from_spec(parsed, scene, scene_name="scene.3dm", spec_name="spec.json")
    out: dict[str, Any] = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"][0]
    return out


# --- Single block: a stone column with a bronze weight over its inner edge --------------------


def column(b: Any) -> None:
    b.box("column", "Walls", (0, 0, 0), (0.4, 0.5, 2.0), "stone")
    b.box("weight", "Walls", (0.0, 0, 2.0), (0.15, 0.5, 2.3), "bronze")
    b.line("axis", "Axes", (0.4, 0, 0), (0.4, 0.5, 0))


def test_single_block_stores_housner_general_for_both_impacts(tmp_path: Path) -> None:
    mech = {
        "id": "S",
        "groups": [
            {"objects": ["column"], "density": 2400},
            {"objects": ["weight"], "density": 8000},
        ],
        "axis": {"object": "axis"},
    }
    s = run(scene_of(tmp_path, column), mech)
    # By hand: composite rectangles (x from, x to, z from, z to, density) in the x-z plane.
    rects = [(0.0, 0.4, 0.0, 2.0, 2400.0), (0.0, 0.15, 2.0, 2.3, 8000.0)]
    ms = [(x1 - x0) * (z1 - z0) * 0.5 * rho for x0, x1, z0, z1, rho in rects]
    cs = [np.array([(x0 + x1) / 2, (z0 + z1) / 2]) for x0, x1, z0, z1, _ in rects]
    m = sum(ms)
    g = sum(mk * ck for mk, ck in zip(ms, cs)) / m
    i_g = sum(
        mk * ((x1 - x0) ** 2 + (z1 - z0) ** 2) / 12 + mk * float((ck - g) @ (ck - g))
        for mk, ck, (x0, x1, z0, z1, _) in zip(ms, cs, rects)
    )
    o_pos, o_neg = np.array([0.4, 0.0]), np.array([0.0, 0.0])
    r_pos, r_neg = g - o_pos, g - o_neg
    # theory §3.1: eta = (I_G + M r_OG . r_O'G) / I_O' with O the old and O' the new pivot.
    to_neg = (i_g + m * float(r_pos @ r_neg)) / (i_g + m * float(r_neg @ r_neg))
    to_pos = (i_g + m * float(r_neg @ r_pos)) / (i_g + m * float(r_pos @ r_pos))
    assert s["eta_to_negative"] == pytest.approx(to_neg, rel=1e-10)
    assert s["eta_to_positive"] == pytest.approx(to_pos, rel=1e-10)
    assert s["eta"] == pytest.approx(max(to_neg, to_pos), rel=1e-12)  # unchanged rule
    assert abs(to_neg / to_pos - 1.0) > 1e-3


# --- Three blocks: a frame with unequal columns --------------------------------------------------

RECTS = (  # (x from, x to, z from, z to) of the left column, the beam, the right column
    (0.0, 0.5, 0.0, 4.0),
    (0.0, 4.3, 4.0, 4.5),
    (3.5, 4.3, 0.0, 4.0),
)
RHO, DEPTH = 2000.0, 1.0
POS = {"A": (0.5, 0.0), "B": (0.0, 4.0), "C": (3.5, 4.0), "D": (4.3, 0.0)}
NEG = {"A": (0.0, 0.0), "B": (0.5, 4.0), "C": (4.3, 4.0), "D": (3.5, 0.0)}


def stepped_frame(b: Any) -> None:
    for name, (x0, x1, z0, z1) in zip(("col_left", "beam", "col_right"), RECTS):
        b.box(name, "Frame", (x0, 0, z0), (x1, DEPTH, z1), "stone")


def hinges3(h: dict[str, tuple[float, float]]) -> dict[str, list[float]]:
    return {k: [x, 0.5, z] for k, (x, z) in h.items()}


def newton_impact(old: dict[str, Any], new: dict[str, Any]) -> float:
    """Block 1's angular velocity after/before a plastic impact onto the ``new`` hinges.

    Nine velocities (v_x, v_z, omega per block) and eight impulse components (at A', B', C',
    D') from nine momentum balances and eight velocity constraints of the new hinge set.
    """
    m = [RHO * DEPTH * (x1 - x0) * (z1 - z0) for x0, x1, z0, z1 in RECTS]
    g = [np.array([(x0 + x1) / 2, (z0 + z1) / 2]) for x0, x1, z0, z1 in RECTS]
    i_g = [mk * ((x1 - x0) ** 2 + (z1 - z0) ** 2) / 12 for mk, (x0, x1, z0, z1) in zip(m, RECTS)]
    jay = lambda r: np.array([-r[1], r[0]])  # noqa: E731  (omega x r in the plane)
    a, b, c, d = (np.array(old[k]) for k in "ABCD")
    # Old mode with omega1 = 1: omega2 and omega3 from v_C = v_B + w2 J(C-B) = w3 J(C-D).
    v_b = jay(b - a)
    sol = np.linalg.solve(np.column_stack([jay(c - b), -jay(c - d)]), -v_b)
    w_old = [1.0, sol[0], sol[1]]
    v_old = [jay(g[0] - a), v_b + sol[0] * jay(g[1] - b), sol[1] * jay(g[2] - d)]
    a2, b2, c2, d2 = (np.array(new[k]) for k in "ABCD")
    # Unknowns: [v1(2), w1, v2(2), w2, v3(2), w3, PA(2), PB(2), PC(2), PD(2)]
    n = 17
    mat, rhs = np.zeros((n, n)), np.zeros(n)
    row = 0
    # impulses on each block: (index of impulse, sign, point)
    loads = [
        [(9, 1.0, a2), (11, -1.0, b2)],
        [(11, 1.0, b2), (13, -1.0, c2)],
        [(13, 1.0, c2), (15, 1.0, d2)],
    ]
    for k in range(3):
        for axis in range(2):
            mat[row, 3 * k + axis] = m[k]
            for idx, sign, _ in loads[k]:
                mat[row, idx + axis] -= sign
            rhs[row] = m[k] * v_old[k][axis]
            row += 1
        mat[row, 3 * k + 2] = i_g[k]
        for idx, sign, point in loads[k]:
            r = point - g[k]
            mat[row, idx] -= sign * -r[1]  # cross(r, P) = r_x P_z - r_z P_x
            mat[row, idx + 1] -= sign * r[0]
        rhs[row] = i_g[k] * w_old[k]
        row += 1

    def point_velocity(k: int, p: np.ndarray) -> np.ndarray:
        # Coefficients of the velocity of point p of block k in the unknowns (2 x 17).
        out = np.zeros((2, n))
        out[0, 3 * k], out[1, 3 * k + 1] = 1.0, 1.0
        out[:, 3 * k + 2] = jay(p - g[k])
        return out

    for coeff in (
        point_velocity(0, a2),
        point_velocity(2, d2),
        point_velocity(0, b2) - point_velocity(1, b2),
        point_velocity(1, c2) - point_velocity(2, c2),
    ):
        mat[row : row + 2] = coeff
        row += 2
    assert row == n
    x = np.linalg.solve(mat, rhs)
    return float(x[2] / w_old[0])


def frame_spec() -> dict[str, Any]:
    return {
        "id": "P",
        "typology": "multi_block",
        "blocks": [
            [{"objects": ["col_left"], "density": RHO}],
            [{"objects": ["beam"], "density": RHO}],
            [{"objects": ["col_right"], "density": RHO}],
        ],
        "hinges": hinges3(POS),
        "hinges_negative": hinges3(NEG),
    }


def test_frame_with_unequal_columns_stores_both_impact_directions(tmp_path: Path) -> None:
    p = run(scene_of(tmp_path, stepped_frame), frame_spec())
    to_neg, to_pos = newton_impact(POS, NEG), newton_impact(NEG, POS)
    assert p["eta_to_negative"] == pytest.approx(to_neg, rel=1e-10)
    assert p["eta_to_positive"] == pytest.approx(to_pos, rel=1e-10)
    assert abs(to_neg / to_pos - 1.0) > 1e-3  # the two impacts differ
    assert p["eta"] == p["eta_to_negative"]  # unchanged: the positive-to-negative value
    model = to_rocking_model(parse_constants({"mechanisms": [p]}).mechanisms[0])
    assert model.eta_to_negative == p["eta_to_negative"]
    assert model.eta_to_positive == p["eta_to_positive"]


def test_symmetric_frame_stores_one_eta(tmp_path: Path) -> None:
    def frame(b: Any) -> None:
        b.box("col_left", "Frame", (0, 0, 0), (0.5, 1, 4), "stone")
        b.box("col_right", "Frame", (3.5, 0, 0), (4.0, 1, 4), "stone")
        b.box("beam", "Frame", (0, 0, 4), (4.0, 1, 4.5), "stone")

    mech = frame_spec()
    mech["hinges"] = hinges3({"A": (0.5, 0), "B": (0, 4), "C": (3.5, 4), "D": (4, 0)})
    mech["hinges_negative"] = hinges3({"A": (0, 0), "B": (0.5, 4), "C": (4, 4), "D": (3.5, 0)})
    p = run(scene_of(tmp_path, frame), mech)
    assert "eta_to_negative" not in p and "eta_to_positive" not in p


# --- The constants file and the solver model ----------------------------------------------------

BASE = {"id": "W", "p_eq": 2.0, "lam": 0.2}


@pytest.mark.parametrize(
    ("extra", "field", "words"),
    [
        ({"eta": 0.9, "eta_to_negative": 0.9}, "eta_to_positive", "go together"),
        ({"eta_to_negative": 0.9, "eta_to_positive": 0.8}, "eta", "need eta"),
        ({"eta": 0.95, "eta_to_negative": 0.9, "eta_to_positive": 0.8}, "eta", "not between"),
        (
            {"rocking": "one_sided", "eta": -0.5, "eta_to_negative": 0.9, "eta_to_positive": 0.8},
            "eta_to_negative",
            "two-sided rocking only",
        ),
        ({"eta": 0.9, "eta_to_negative": 1.2, "eta_to_positive": 0.9}, "eta_to_negative", "1"),
    ],
)
def test_constants_file_checks_the_two_etas(extra: dict[str, Any], field: str, words: str) -> None:
    with pytest.raises(InputError) as err:
        parse_constants([dict(BASE, **extra)])
    assert err.value.field is not None and err.value.field.endswith(field)
    assert words in str(err.value)


def test_rocking_model_checks_the_two_etas() -> None:
    side = RockingSide(2.0, 0.2)
    with pytest.raises(InputError, match="go together"):
        RockingModel(side, eta=0.9, eta_to_negative=0.9)
    with pytest.raises(InputError, match="eta_to_positive"):
        RockingModel(side, eta=0.9, eta_to_negative=0.9, eta_to_positive=1.5)
    model = RockingModel(side, eta=0.9, eta_to_negative=0.9, eta_to_positive=0.85)
    assert (model.eta_to_negative, model.eta_to_positive) == (0.9, 0.85)
