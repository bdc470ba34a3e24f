"""Vault and roof thrusts (theory §5).

Vault thrusts come from a **thrust table held as data** (``data/vault_thrust.json``): for each
construction class a-e and rise/span ratio it gives the vertical load ``v`` and horizontal
thrust ``h`` that one vault bay puts on the wall it springs from, per square metre of the
bay's plan area [N/m²]. Users may load their own table (for example Ungewitter's values)
in the same format. Between tabulated rise/span ratios the values are interpolated
linearly; outside the table's range is an error.

The shipped table is the documented engineering estimate of theory §5 (not Ungewitter's
table, which could not be found): each diagonal rib band is a parabolic arch carrying a
quarter of the vault's weight per springing, its thrust resolved onto the wall normal. For a
bay of plan area ``A = s_n s_p`` (``s_n`` normal to the wall), rise ``f`` and weight
``W = w A``, the wall (two springings) receives ``V = W/2`` and ``H = W s_n/(8 f)``. The
shell weight per plan area is ``w = rho g t (1 + 8/3 (f/s_n)**2)`` (parabolic arc length over
its chord). Classes (the method's a-e): a: half light brick (125 mm); b: half strong or
three-quarter light brick (190 mm); c: three-quarter strong or one light brick (250 mm);
d: one strong brick or 200 mm sandstone; e: 300 mm rubble.

Roof thrust (pitched roof, rafters pinned at ridge and wall heads): ``H = W_r L/(8 f)`` for
the whole roof weight ``W_r`` over span ``L`` and rise ``f`` from its bounding box; a tied
truss gives no thrust.
"""

import json
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple, Union

from shared_schema.constants import json_document
from shared_schema.errors import InputError
from shared_schema.rules import G, check_file
from shared_schema.text import decode_text

__all__ = ["DEFAULT_TABLE", "ThrustTable", "estimate_rows", "roof_thrust"]

#: What a thrust table file must be, for the messages on a file that is not one.
THRUST_TABLE_EXPECTED = (
    'a thrust table (JSON text, {"source": ..., "rows": [{"class", "rise_span", "v_N_m2", '
    '"h_N_m2"}, ...]})'
)
#: The shipped table.
DEFAULT_TABLE = Path(__file__).resolve().parent / "data" / "vault_thrust.json"
#: Construction classes of the estimate: shell thickness [m] and density [kg/m³].
CLASSES = {
    "a": (0.125, 1400.0),
    "b": (0.190, 1500.0),
    "c": (0.250, 1600.0),
    "d": (0.200, 2300.0),
    "e": (0.300, 2000.0),
}
#: Rise/span ratios of the shipped table.
RISE_SPAN = (0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5)


def estimate_rows() -> List[Dict[str, Any]]:
    """Rows of the §5 estimate: class, rise_span, v and h per plan area [N/m²]."""
    rows = []
    for cls, (t, rho) in CLASSES.items():
        for r in RISE_SPAN:
            w = rho * G * t * (1.0 + 8.0 / 3.0 * r * r)
            rows.append({"class": cls, "rise_span": r, "v_N_m2": 0.5 * w, "h_N_m2": w / (8.0 * r)})
    return rows


class ThrustTable:
    """Vault thrust per plan area by construction class and rise/span ratio.

    Parameters
    ----------
    data : dict
        ``{"source": str, "rows": [{"class", "rise_span", "v_N_m2", "h_N_m2"}, ...]}``.
    """

    def __init__(self, data: Dict[str, Any], name: str = "thrust table") -> None:
        self.name = name
        self.source = str(data.get("source", ""))
        table: Dict[str, List[Tuple[float, float, float]]] = {}
        try:
            for row in data["rows"]:
                key = str(row["class"])
                table.setdefault(key, []).append(
                    (float(row["rise_span"]), float(row["v_N_m2"]), float(row["h_N_m2"]))
                )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed row ({exc}); see the module docs", name) from None
        for key in table:
            table[key].sort()
        self._table = table

    @classmethod
    def load(cls, path: Optional[Union[str, Path]] = None) -> "ThrustTable":
        """Read a table file (default: the shipped estimate)."""
        p = Path(path) if path is not None else DEFAULT_TABLE
        check_file(p, "thrust_table")
        try:
            raw = p.read_bytes()
        except OSError as exc:
            raise InputError(f"cannot read {p}: {exc.strerror or exc}", "thrust_table") from None
        # issue #36: a table that is not UTF-8 JSON was answered in the codec's words
        text = decode_text(raw, p.name, "thrust_table", THRUST_TABLE_EXPECTED)
        try:
            data = json_document(text)
        except InputError as exc:
            raise InputError(
                f"{p.name}: {exc.reason}; expected {THRUST_TABLE_EXPECTED}", "thrust_table"
            ) from None
        if not isinstance(data, dict):
            raise InputError(
                f"{p.name}: the top level is {type(data).__name__}, not an object; expected "
                f"{THRUST_TABLE_EXPECTED}",
                "thrust_table",
            )
        return cls(data, name=str(p.name))

    @property
    def classes(self) -> List[str]:
        """Construction classes in the table."""
        return sorted(self._table)

    def per_area(
        self, construction_class: str, rise_span: float, where: str
    ) -> Tuple[float, float]:
        """Return load and thrust per plan area [N/m²] at ``rise_span``; errors name ``where``."""
        rows = self._table.get(construction_class)
        if rows is None:
            raise InputError(
                f"unknown vault class {construction_class!r}; the table has {self.classes}", where
            )
        lo, hi = rows[0][0], rows[-1][0]
        if not lo <= rise_span <= hi:
            raise InputError(
                f"rise/span {rise_span:.3f} is outside the thrust table's range [{lo}, {hi}]",
                where,
            )
        for (r0, v0, h0), (r1, v1, h1) in zip(rows[:-1], rows[1:]):
            if r0 <= rise_span <= r1:
                w = 0.0 if r1 == r0 else (rise_span - r0) / (r1 - r0)
                return v0 + w * (v1 - v0), h0 + w * (h1 - h0)
        return rows[0][1], rows[0][2]


def roof_thrust(weight: float, span: float, rise: float, tied: bool) -> float:
    """Horizontal thrust [N] of a pitched roof of weight [N], span and rise [m] (theory §5)."""
    if tied:
        return 0.0
    if rise <= 0.0 or span <= 0.0:
        raise InputError(f"roof span {span:.3f} m and rise {rise:.3f} m must be > 0", "roof")
    return weight * span / (8.0 * rise)


if __name__ == "__main__":  # pragma: no cover - regenerates the shipped table
    doc = {
        "source": "rockmech estimate of theory §5 (parabolic diagonal arches; not Ungewitter)",
        "units": {"v_N_m2": "N per m^2 of bay plan area", "h_N_m2": "N per m^2 of bay plan area"},
        "rows": estimate_rows(),
    }
    DEFAULT_TABLE.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
