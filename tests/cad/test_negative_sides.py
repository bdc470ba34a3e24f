"""The negative side of every two-sided typology under an eccentric load, through the CAD path.

Every reference here is independent of the code under test: hand-worked closed forms
(composite rectangles, theory Eqs. 7-10 and 18-23 on the mirrored geometry) or a separate
numerical model that moves the blocks' corners, solves the closure with scipy, and takes
every derivative of the potential energy by finite differences.

``single_block_loaded`` rocks two-sided only with tie-bars alone, and its negative side is
then the plain wall's (the bars go slack on that swing): ``tests/cad/test_tie_pulls.py``.

The file's sign convention (``shared_schema.constants``): ``I0``, ``K``, ``Q``, ``phi_cr``,
``p_eq``, ``lam`` and ``phi_ov`` are magnitudes on both sides; ``M_F`` is signed in the
mechanism's positive sense on both sides, so a moment that drives the negative side
towards collapse is negative in ``negative.M_F``.
"""

from __future__ import annotations

import cmath
import json
import math
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
from cad_scenes import BUILD
from scipy.optimize import brentq, fsolve

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scene_3dm import Scene
from shared_schema.spec import parse_spec

G = 9.80665


def scene_of(tmp_path: Path, fill: Callable[[Any], None]) -> Scene:
    b = BUILD.Builder("test")
    fill(b)
    return Scene.from_3dm(b.write(tmp_path / "scene.3dm"))


def constants(scene: Scene, *mechs: dict[str, Any]) -> dict[str, Any]:
    spec = parse_spec(json.dumps({"mechanisms": list(mechs)}), "spec.json")
    cf = constants_from_spec(spec, scene, scene_name="scene.3dm", spec_name="spec.json")
    return {m["id"]: m for m in json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"]}


def d1(f: Callable[[float], Any], x: float, h: float = 2e-3) -> Any:
    """Central first difference with one Richardson step (error O(h^4))."""

    def c(s: float) -> Any:
        return (f(x + s) - f(x - s)) / (2 * s)

    return (4 * c(h / 2) - c(h)) / 3


def d2(f: Callable[[float], float], x: float, h: float = 4e-3) -> float:
    """Central second difference with one Richardson step (error O(h^4))."""

    def c(s: float) -> float:
        return (f(x + s) - 2 * f(x) + f(x - s)) / (s * s)

    return float((4 * c(h / 2) - c(h)) / 3)


# --- Two-block wall (A3): slab bearing on the inner third of the wall top ---------------------

B, H, LEN, RHO = 0.3, 4.0, 2.0, 1800.0
SLAB_X = (-4.0, 0.1)  # the slab bears on 0 <= x <= 0.1 of the 0.3 m top face
SLAB_T, SLAB_RHO, F_MT = 0.2, 2400.0, 1.0e5


def eccentric_wall(b: Any) -> None:
    b.box("wall", "Walls", (0, 0, 0), (B, LEN, H), "brick")
    b.box("slab", "Floors", (SLAB_X[0], 0, H), (SLAB_X[1], LEN, H + SLAB_T), "concrete")
    b.line("axis", "Axes", (B, 0, 0), (B, LEN, 0))


def two_block_spec(eccentricity: str) -> dict[str, Any]:
    return {
        "id": "T",
        "typology": "two_block",
        "groups": [{"objects": ["wall"], "density": RHO}],
        "axis": {"object": "axis"},
        "f_mt": F_MT,
        "eccentricity": eccentricity,
        "overburden": {"objects": ["slab"], "density": SLAB_RHO, "tributary": 0.5},
    }


def wall_by_hand() -> dict[str, float]:
    """N, its point and the hinge height of the eccentric wall (Eq. 17), by hand."""
    n = 0.5 * SLAB_RHO * G * (SLAB_X[1] - SLAB_X[0]) * LEN * SLAB_T
    w = RHO * G * B * H * LEN
    top = n + F_MT * LEN * B
    h_c = H / (1 + math.sqrt(top / (top + w)))  # theory Eq. 17
    return {"N": n, "x_N": 0.5 * SLAB_X[1], "h_c": h_c}


def eqs_18_to_23(h_c: float, n: float, xi: float) -> dict[str, float]:
    """Theory Eqs. 18-23 for a rectangular strip, N at xi*b from the top hinge."""
    h1, h2 = h_c, H - h_c
    m1, m2 = RHO * LEN * B * h1, RHO * LEN * B * h2
    r1, r2 = 0.5 * math.hypot(B, h1), 0.5 * math.hypot(B, h2)
    a1, a2 = math.atan(B / h1), math.atan(B / h2)
    i0 = m1 * (B * B + h1 * h1) / 3 + (r1 / r2) ** 2 * m2 * (B * B + h2 * h2) / 3
    k = r1 * (G * (m1 + 2 * m2) + 2 * n + (G * m2 + 2 * n) * r1 / r2)
    q = (m1 + m2) * r1
    m_f = n * xi * B * math.cos(a2) * r1 / r2  # drives this side's collapse
    return {"I0": i0, "K": k, "Q": q, "phi_cr": a1, "M_F": m_f}


def test_two_block_negative_side_with_eccentric_overburden_is_eq_23_on_the_mirrored_wall(
    tmp_path: Path,
) -> None:
    hand = wall_by_hand()
    t = constants(scene_of(tmp_path, eccentric_wall), two_block_spec("static_moment"))["T"]
    # Positive side: H at the outer top edge x = b, N at xi b from it.
    for name, xi, sign in (
        ("positive", (B - hand["x_N"]) / B, 1.0),
        ("negative", hand["x_N"] / B, -1.0),
    ):
        ref = eqs_18_to_23(hand["h_c"], hand["N"], xi)
        side = t[name]
        for key in ("I0", "K", "Q", "phi_cr"):
            assert side[key] == pytest.approx(ref[key], rel=1e-9), (name, key)
        # The eccentric N drives both sides towards collapse (Eq. 23 on each side's own
        # geometry); the file signs it in the positive sense.
        assert side["M_F"] == pytest.approx(sign * ref["M_F"], rel=1e-9), name
        lam = (ref["K"] * ref["phi_cr"] - ref["M_F"]) / (G * ref["Q"])
        assert side["lam"] == pytest.approx(lam, rel=1e-9), name
        assert side["phi_ov"] == pytest.approx(ref["phi_cr"] - ref["M_F"] / ref["K"], rel=1e-9)


class MirroredWall:
    """Independent exact model of the wall rocking *inward*, from its moved corners.

    Block 1 turns about O' (the base inner edge, x = 0) by ``phi`` towards -x, block 2 is
    pinned to it at C' (outer face at h_c) and turns so that H' (top inner edge) keeps its
    x; N acts at its own point of block 2 (the exact linearisation, ``"potential"``).
    """

    def __init__(self, h_c: float, n: float, x_n: float) -> None:
        self.O, self.C, self.H = complex(0, 0), complex(B, h_c), complex(0, H)
        self.P = complex(x_n, H)
        self.one = [0, B, complex(B, h_c), complex(0, h_c)]
        self.two = [complex(0, h_c), complex(B, h_c), complex(B, H), complex(0, H)]
        self.m = [RHO * LEN * B * h_c, RHO * LEN * B * (H - h_c)]
        hk = (h_c, H - h_c)
        self.i_g = [m * (B * B + h * h) / 12 for m, h in zip(self.m, hk)]
        self.n = n

    def config(self, phi: float) -> tuple[complex, complex, complex, float]:
        rot1 = cmath.exp(1j * phi)  # anticlockwise: points above O' move towards -x
        c = self.O + (self.C - self.O) * rot1

        def gap(beta: float) -> float:
            return (c + (self.H - self.C) * cmath.exp(1j * beta)).real - self.H.real

        beta = brentq(gap, -1.0, 1.0, xtol=1e-15, rtol=8.9e-16)
        rot2 = cmath.exp(1j * beta)
        g1 = sum(self.O + (p - self.O) * rot1 for p in self.one) / 4
        g2 = sum(c + (p - self.C) * rot2 for p in self.two) / 4
        return g1, g2, c + (self.P - self.C) * rot2, beta

    def V(self, phi: float) -> float:
        g1, g2, p, _ = self.config(phi)
        return G * (self.m[0] * g1.imag + self.m[1] * g2.imag) + self.n * p.imag

    def constants(self) -> dict[str, float]:
        dv = lambda x: d1(self.V, x)  # noqa: E731
        phi_cr = brentq(dv, 0.02, 0.5, xtol=1e-14)
        u1 = d1(lambda x: self.config(x)[0], phi_cr)
        u2 = d1(lambda x: self.config(x)[1], phi_cr)
        w2 = d1(lambda x: self.config(x)[3], phi_cr)
        i0 = self.i_g[0] + self.m[0] * abs(u1) ** 2 + self.i_g[1] * w2**2 + self.m[1] * abs(u2) ** 2
        k = -d2(self.V, phi_cr)
        q = -(self.m[0] * u1.real + self.m[1] * u2.real)  # towards -x
        return {"I0": i0, "K": k, "Q": q, "phi_cr": phi_cr, "lam": k * phi_cr / (G * q)}


def test_two_block_negative_side_potential_matches_an_independent_exact_model(
    tmp_path: Path,
) -> None:
    hand = wall_by_hand()
    scene = scene_of(tmp_path, eccentric_wall)
    t = constants(scene, two_block_spec("potential"))["T"]
    ref = MirroredWall(hand["h_c"], hand["N"], hand["x_N"]).constants()
    for key in ("I0", "K", "Q", "phi_cr", "lam"):
        assert t["negative"][key] == pytest.approx(ref[key], rel=1e-7), key
    assert t["negative"]["M_F"] == 0.0
    # The method's static moment (Eq. 23) must agree with the exact linearisation on the
    # negative side as it does on the positive one: within 1 % here (slender wall with
    # f_mt, theory §2.3). Before the sign fix the negative side was 9.7 % too high.
    static = constants(scene, two_block_spec("static_moment"))["T"]
    for side in ("positive", "negative"):
        ratio = static[side]["lam"] / t[side]["lam"]
        assert abs(ratio - 1.0) < 0.01, (side, ratio)
        ratio = static[side]["phi_ov"] / t[side]["phi_ov"]
        assert abs(ratio - 1.0) < 0.01, (side, ratio)


def test_two_block_centred_load_is_symmetric_and_stores_one_side(tmp_path: Path) -> None:
    def centred(b: Any) -> None:
        b.box("wall", "Walls", (0, 0, 0), (B, LEN, H), "brick")
        b.box("slab", "Floors", (0, 0, H), (B, LEN, H + SLAB_T), "concrete")
        b.line("axis", "Axes", (B, 0, 0), (B, LEN, 0))

    t = constants(scene_of(tmp_path, centred), two_block_spec("static_moment"))["T"]
    assert t["positive"]["M_F"] > 0.0
    assert "negative" not in t  # the mirror image: same lam and phi_ov on both sides


# --- Single block (A1): a column carrying an eccentric bronze weight --------------------------

COL = (0.4, 0.5, 2.0)  # x, y, z extents of the stone column [m]
ECC = (0.0, 0.15, 0.3)  # bronze weight on the column top over 0 <= x <= 0.15, 0.3 m high
RHO_COL, RHO_ECC = 2400.0, 8000.0


def column_scene(b: Any) -> None:
    b.box("column", "Walls", (0, 0, 0), COL, "stone")
    b.box("weight", "Walls", (ECC[0], 0, COL[2]), (ECC[1], COL[1], COL[2] + ECC[2]), "bronze")
    b.line("axis", "Axes", (COL[0], 0, 0), (COL[0], COL[1], 0))


def boxes_about_edge(x_edge: float) -> dict[str, float]:
    """M, R, alpha, I_O of the column + weight about the base edge at x = x_edge, by hand."""
    parts = [  # (mass, x_c, z_c, width, height)
        (RHO_COL * COL[0] * COL[1] * COL[2], COL[0] / 2, COL[2] / 2, COL[0], COL[2]),
        (RHO_ECC * (ECC[1] - ECC[0]) * COL[1] * ECC[2], (ECC[0] + ECC[1]) / 2,
         COL[2] + ECC[2] / 2, ECC[1] - ECC[0], ECC[2]),
    ]  # fmt: skip
    m = sum(p[0] for p in parts)
    xg = sum(p[0] * p[1] for p in parts) / m
    zg = sum(p[0] * p[2] for p in parts) / m
    i_o = sum(
        mk * (w * w + h * h) / 12 + mk * ((x - x_edge) ** 2 + z * z) for mk, x, z, w, h in parts
    )
    r = math.hypot(xg - x_edge, zg)
    return {"M": m, "R": r, "alpha": math.atan2(abs(xg - x_edge), zg), "I_O": i_o}


def test_single_block_negative_side_with_an_eccentric_weight_is_housner_about_the_other_edge(
    tmp_path: Path,
) -> None:
    mech = {
        "id": "S",
        "groups": [
            {"objects": ["column"], "density": RHO_COL},
            {"objects": ["weight"], "density": RHO_ECC},
        ],
        "axis": {"object": "axis"},
    }
    s = constants(scene_of(tmp_path, column_scene), mech)["S"]
    for name, edge in (("positive", COL[0]), ("negative", 0.0)):
        ref = boxes_about_edge(edge)
        side = s[name]
        assert side["I0"] == pytest.approx(ref["I_O"], rel=1e-10), name  # Eq. 7
        assert side["K"] == pytest.approx(ref["M"] * G * ref["R"], rel=1e-10), name  # Eq. 8
        assert side["phi_cr"] == pytest.approx(ref["alpha"], rel=1e-10), name  # Eq. 9
        assert side["Q"] == pytest.approx(ref["M"] * ref["R"], rel=1e-10), name  # Eq. 10
        assert side["lam"] == pytest.approx(ref["alpha"], rel=1e-10), name
        assert side["phi_ov"] == pytest.approx(ref["alpha"], rel=1e-10), name
        assert side["M_F"] == 0.0
    # The weight sits over the inner edge, nearer the negative side's axis: that side is
    # the easier one to start.
    assert s["negative"]["lam"] < s["positive"]["lam"]


# --- Three blocks (A4): a portal frame with a weight hung on the left column's outer face ----
# (A weight on the beam alone would not do: the beam of this parallelogram only translates,
# so where its mass sits does not matter.)


def loaded_frame(b: Any) -> None:
    b.box("col_left", "Frame", (0, 0, 0), (0.5, 1, 4), "stone")
    b.box("col_right", "Frame", (3.5, 0, 0), (4.0, 1, 4), "stone")
    b.box("beam", "Frame", (0, 0, 4), (4.0, 1, 4.5), "stone")
    b.box("weight", "Frame", (-0.3, 0, 2.0), (0.0, 1, 2.5), "bronze")


FRAME_POS = {"A": [0.5, 0.5, 0], "B": [0, 0.5, 4], "C": [3.5, 0.5, 4], "D": [4, 0.5, 0]}
FRAME_NEG = {"A": [0, 0.5, 0], "B": [0.5, 0.5, 4], "C": [4, 0.5, 4], "D": [3.5, 0.5, 0]}


def frame_spec() -> dict[str, Any]:
    return {
        "id": "P",
        "typology": "multi_block",
        "blocks": [
            [{"objects": ["col_left"], "density": 2000}, {"objects": ["weight"], "density": 7800}],
            [{"objects": ["beam"], "density": 2000}],
            [{"objects": ["col_right"], "density": 2000}],
        ],
        "hinges": FRAME_POS,
        "hinges_negative": FRAME_NEG,
    }


class FrameModel:
    """Independent four-bar model: closure by ``fsolve``, derivatives by finite differences.

    Rigid rectangles (x from, x to, z from, z to, density) per block; ``ccw`` is the sense
    of block 1's rotation and ``toward`` the sign of x along which Q is measured.
    """

    blocks = (
        [(0.0, 0.5, 0.0, 4.0, 2000.0), (-0.3, 0.0, 2.0, 2.5, 7800.0)],
        [(0.0, 4.0, 4.0, 4.5, 2000.0)],
        [(3.5, 4.0, 0.0, 4.0, 2000.0)],
    )

    def __init__(self, hinges: dict[str, list[float]], ccw: float, toward: float) -> None:
        self.A, self.B0, self.C0, self.D = (np.array([hinges[k][0], hinges[k][2]]) for k in "ABCD")
        self.ccw, self.toward = ccw, toward
        self.mass, self.com0, self.i_g = [], [], []
        for rects in self.blocks:
            ms = [(x1 - x0) * (z1 - z0) * rho for x0, x1, z0, z1, rho in rects]
            cs = [np.array([(x0 + x1) / 2, (z0 + z1) / 2]) for x0, x1, z0, z1, _ in rects]
            m = sum(ms)
            c = sum(mi * ci for mi, ci in zip(ms, cs)) / m
            i_g = sum(
                mi * ((x1 - x0) ** 2 + (z1 - z0) ** 2) / 12 + mi * float((ci - c) @ (ci - c))
                for mi, ci, (x0, x1, z0, z1, _) in zip(ms, cs, rects)
            )
            self.mass.append(m)
            self.com0.append(c)
            self.i_g.append(i_g)
        self._guess = self.C0.copy()

    @staticmethod
    def rot(t: float) -> np.ndarray:
        return np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])

    def config(self, theta: float) -> tuple[list[np.ndarray], np.ndarray]:
        t1 = self.ccw * theta
        b = self.A + self.rot(t1) @ (self.B0 - self.A)
        l2, l3 = np.linalg.norm(self.C0 - self.B0), np.linalg.norm(self.C0 - self.D)

        def closure(c: np.ndarray) -> list[float]:
            return [np.linalg.norm(c - b) - l2, np.linalg.norm(c - self.D) - l3]

        c = fsolve(closure, self.C0, xtol=1e-13)
        ang = lambda v: math.atan2(v[1], v[0])  # noqa: E731
        t2 = ang(c - b) - ang(self.C0 - self.B0)
        t3 = ang(c - self.D) - ang(self.C0 - self.D)
        coms = [
            self.A + self.rot(t1) @ (self.com0[0] - self.A),
            b + self.rot(t2) @ (self.com0[1] - self.B0),
            self.D + self.rot(t3) @ (self.com0[2] - self.D),
        ]
        return coms, np.array([t1, t2, t3])

    def V(self, theta: float) -> float:
        coms, _ = self.config(theta)
        return G * sum(m * float(c[1]) for m, c in zip(self.mass, coms))

    def constants(self) -> dict[str, float]:
        phi_cr = brentq(lambda x: d1(self.V, x), 0.01, 0.5, xtol=1e-14)
        u = d1(lambda x: np.concatenate(self.config(x)[0]), phi_cr).reshape(3, 2)
        w = d1(lambda x: self.config(x)[1], phi_cr)
        i0 = sum(
            m * float(ui @ ui) + ig * wi**2 for m, ui, ig, wi in zip(self.mass, u, self.i_g, w)
        )
        q = self.toward * sum(m * float(ui[0]) for m, ui in zip(self.mass, u))
        k = -d2(self.V, phi_cr)
        return {"I0": i0, "K": k, "Q": q, "phi_cr": phi_cr, "lam": k * phi_cr / (G * q)}


def test_multi_block_negative_side_with_an_eccentric_weight_matches_an_independent_model(
    tmp_path: Path,
) -> None:
    p = constants(scene_of(tmp_path, loaded_frame), frame_spec())["P"]
    # Positive sway (+x): columns turn clockwise; negative sway (-x): anticlockwise.
    for name, hinges, ccw, toward in (
        ("positive", FRAME_POS, -1.0, 1.0),
        ("negative", FRAME_NEG, 1.0, -1.0),
    ):
        ref = FrameModel(hinges, ccw, toward).constants()
        for key in ("I0", "K", "Q", "phi_cr", "lam"):
            assert p[name][key] == pytest.approx(ref[key], rel=1e-7), (name, key)
        assert p[name]["M_F"] == 0.0
    assert p["negative"]["lam"] != pytest.approx(p["positive"]["lam"], rel=1e-3)
