"""Virtual-work quantities at rest for the code check (docs/theory.md §11.1), per typology.

References are closed forms: a rectangular block (alpha0 = b/h, e* = 3/4 over the solid,
1 by the blocks of Circolare 2019 [C8.7.1.5]), a symmetric two-block strip (a triangular
displacement shape: e* = 3/4 over the solid, 1 by its two blocks, whose centres move alike;
alpha0 = 2b/h1) and a portal frame whose beam translates with the column tops.
"""

import json
from pathlib import Path

import pytest

from cad_maths.mechanisms.base import virtual_work_of
from cad_maths.mechanisms.multi_block import four_bar_constants, portal_frame
from cad_maths.mechanisms.two_block import PlanarBody, rectangular_two_block
from shared_schema.constants import parse_constants
from shared_schema.errors import InputError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def e_star(vw: dict) -> float:
    return float(vw["S"] ** 2 / (vw["mass"] * vw["J"]))


def test_rectangular_block_from_cad_gives_b_over_h_and_three_quarters() -> None:
    pytest.importorskip("rhino3dm")
    from cad_maths.mechanisms.build import constants_from_spec
    from cad_maths.scene_3dm import Scene
    from shared_schema.spec import parse_spec

    spec_path = EXAMPLES / "specs" / "rect_wall.spec.json"
    scene = Scene.from_3dm(EXAMPLES / "scenes" / "rect_wall.3dm")
    spec = parse_spec(spec_path.read_text(encoding="utf-8"), spec_path.name)
    cf = constants_from_spec(spec, scene, scene_name="rect_wall.3dm", spec_name=spec_path.name)
    mech = cf.mechanisms[0]
    vw = mech.positive.virtual_work
    assert vw is not None
    b, h, mass = 0.5, 3.0, 1800.0 * 0.5 * 1.0 * 3.0
    assert vw.alpha0 == pytest.approx(b / h, rel=1e-12)
    assert vw.mass == pytest.approx(mass, rel=1e-12)
    assert vw.S == pytest.approx(mass * h / 2, rel=1e-12)
    assert vw.J == pytest.approx(mass * h * h / 3, rel=1e-12)
    assert vw.S**2 / (vw.mass * vw.J) == pytest.approx(0.75, abs=1e-12)
    # [C8.7.1.5] by blocks: one term, the centre of mass at h/2: J_blocks = m (h/2)², e* = 1.
    assert vw.J_blocks == pytest.approx(mass * (h / 2) ** 2, rel=1e-12)
    # Symmetric block: the negative side equals the positive one and is not stored.
    assert mech.negative is None


def test_symmetric_two_block_strip_is_a_triangle() -> None:
    b, h = 0.3, 4.0
    res = rectangular_two_block(b, h, h / 2, length=1.0, density=1800.0)
    vw = virtual_work_of(res.details, "lam_static_exact")
    assert vw is not None
    mass = 1800.0 * b * h
    assert vw["mass"] == pytest.approx(mass, rel=1e-12)
    # Both centres move by h/4 for a unit rotation of block 1 (block 2 turns by h1/h2 = 1).
    assert vw["S"] == pytest.approx(mass * h / 4, rel=1e-12)
    assert vw["J"] == pytest.approx(mass * (h / 4) ** 2 * 4 / 3, rel=1e-12)
    assert e_star(vw) == pytest.approx(0.75, abs=1e-12)
    # [C8.7.1.5] by blocks: two terms (m/2) (h/4)², so e* = (m h/4)²/(m · m (h/4)²) = 1.
    assert vw["J_blocks"] == pytest.approx(mass * (h / 4) ** 2, rel=1e-12)
    assert vw["alpha0"] == pytest.approx(2 * b / (h / 2), rel=1e-12)


def test_two_block_without_second_moments_has_no_virtual_work() -> None:
    from cad_maths.mechanisms.two_block import two_block_constants

    lower = PlanarBody(1080.0, (-0.15, 1.0), 1080.0 * (0.09 + 4.0) / 12)
    upper = PlanarBody(1080.0, (-0.15, 3.0), 1080.0 * (0.09 + 4.0) / 12)
    res = two_block_constants(lower, upper, (0.0, 0.0), (-0.3, 2.0), (0.0, 4.0))
    assert virtual_work_of(res.details, "lam_static_exact") is None


def test_portal_frame_beam_translates_with_the_column_tops() -> None:
    b, h, span, depth, rho = 0.4, 4.0, 3.0, 0.5, 2000.0
    blocks, pos, _ = portal_frame(b, h, span, depth, rho)
    res = four_bar_constants(blocks, *pos)
    vw = virtual_work_of(res.details, "lam_static")
    assert vw is not None
    m_c, m_b = blocks[0].mass, blocks[1].mass
    # Columns turn about their bases (u_x = h/2, omega = 1); the beam translates by h.
    assert vw["S"] == pytest.approx(2 * m_c * h / 2 + m_b * h, rel=1e-12)
    assert vw["J"] == pytest.approx(2 * m_c * h * h / 3 + m_b * h * h, rel=1e-12)
    # [C8.7.1.5] by blocks: the columns' centres move by h/2, the beam by h.
    assert vw["J_blocks"] == pytest.approx(2 * m_c * (h / 2) ** 2 + m_b * h * h, rel=1e-12)
    assert vw["mass"] == pytest.approx(2 * m_c + m_b, rel=1e-12)
    assert vw["alpha0"] == pytest.approx(b / h, rel=1e-12)


def test_inconsistent_virtual_work_is_rejected_naming_the_field() -> None:
    data = {
        "mechanisms": [
            {
                "id": "W1",
                "positive": {
                    "p_eq": 2.0,
                    "lam": 0.1,
                    "virtual_work": {"alpha0": 0.1, "mass": 1.0, "S": 2.0, "J": 1.0},
                },
            }
        ]
    }
    with pytest.raises(InputError) as err:
        parse_constants(json.dumps(data))
    assert "positive.virtual_work.J" in str(err.value.field)
    assert "exceed" in str(err.value)


def test_virtual_work_with_blocks_moving_more_than_their_masses_is_rejected() -> None:
    # J_blocks > J: the blocks' centres cannot move more than their masses do on average.
    data = {
        "mechanisms": [
            {
                "id": "W1",
                "positive": {
                    "p_eq": 2.0,
                    "lam": 0.1,
                    "virtual_work": {
                        "alpha0": 0.1,
                        "mass": 1.0,
                        "S": 1.5,
                        "J": 3.0,
                        "J_blocks": 4.0,
                    },
                },
            }
        ]
    }
    with pytest.raises(InputError) as err:
        parse_constants(json.dumps(data))
    assert "positive.virtual_work.J_blocks" in str(err.value.field)
    assert "exceeds J" in str(err.value)
