"""The mechanism spec: which objects of a scene form each mechanism, and how.

A spec file says, per mechanism, which objects (by name, layer or id) form its density
groups, where the rotation axis is, which cracks cut off the collapsing part, the rocking
kind, and the added elements that exist: floors, roof, vaults and tie-bars. Only declared
elements are computed; absent sections stay absent in every output. Unknown keys are
errors. Lengths are in metres once the scene is read (file units are converted); points
written in the spec are in metres unless the file's ``units`` says otherwise (``"file"``:
the scene's model units). Densities are in kg/m³, forces in N.

Python 3.9-clean: imported by Rhino 8.
"""

import json
from typing import Any, Dict, List, Literal, Optional, Union

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from shared_schema.constants import Amplification, validation_lines
from shared_schema.errors import InputError
from shared_schema.rules import (
    control_character,
    coordinate_problem,
    eta_problem,
    quantity_note,
    quantity_problem,
)

__all__ = [
    "SPEC_VERSION",
    "SPEC_VERSIONS",
    "TRIBUTARY_DEFAULT",
    "Axis",
    "Crack",
    "DensityGroup",
    "Floor",
    "Hinges",
    "MechanismSpec",
    "Overburden",
    "Roof",
    "SpecFile",
    "TieBar",
    "Vault",
    "parse_spec",
]

#: Format version of spec files written today; a file without ``spec_version`` is read as it.
SPEC_VERSION = "1.0"
#: Versions this reader understands; any other is refused (a newer file may mean other things).
SPEC_VERSIONS = ("1.0",)
#: Share of a floor's, roof's or overburden's weight and inertia a wall carries when the spec
#: does not say (a slab spanning between the wall and one parallel support); stated in a
#: warning whenever it is used.
TRIBUTARY_DEFAULT = 0.5

_STRICT = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False)

#: An object selector: a name, or one of {"name": ...}, {"layer": ...}, {"id": ...}.
Selector = Union[str, Dict[Literal["name", "layer", "id"], str]]
Point3 = List[float]


def _point(value: List[float], what: str) -> List[float]:
    if len(value) != 3:
        raise ValueError(f"{what} must have 3 coordinates [m], got {len(value)}")
    problem = coordinate_problem(value, "in the spec's units")
    if problem is not None:
        raise ValueError(f"{what}: {problem}")
    return value


def _in_range(value: Optional[float], kind: str, zero: bool = False) -> Optional[float]:
    """Check a physical input against ``rules.QUANTITY_RANGES`` (a field validator's body)."""
    if value is None or (zero and value == 0.0):
        return value
    problem = quantity_problem(value, kind)
    if problem is not None:
        raise ValueError(problem)
    return value


def _repeated(selectors: List[Selector]) -> Optional[Selector]:
    """Return the first selector listed more than once, or None."""
    seen: List[Selector] = []
    for sel in selectors:
        if sel in seen:
            return sel
        seen.append(sel)
    return None


def _once(selectors: List[Selector]) -> List[Selector]:
    """Refuse an object listed twice: it would be counted twice (mass, I0 and Q doubled)."""
    twice = _repeated(selectors)
    if twice is not None:
        raise ValueError(
            f"{twice!r} is listed twice; an object listed twice would be counted twice "
            "(its mass, I0 and Q doubled): list each object once"
        )
    return selectors


class _Weighed(BaseModel):
    """Objects of one density: each object listed once, the density in its range."""

    model_config = _STRICT

    @field_validator("density", check_fields=False)
    @classmethod
    def _check_density(cls, value: Optional[float]) -> Optional[float]:
        return _in_range(value, "density")

    @field_validator("objects", check_fields=False)
    @classmethod
    def _check_objects(cls, value: Optional[List[Selector]]) -> Optional[List[Selector]]:
        return value if value is None else _once(value)


class DensityGroup(_Weighed):
    """Objects of one material.

    Attributes
    ----------
    objects : list of selectors
        Objects by name (a string) or ``{"name"|"layer"|"id": ...}``; at least one.
    density : float
        Density [kg/m³], > 0.
    label : str, optional
        Material name for reports (e.g. "stone", "bronze").
    """

    objects: List[Selector] = Field(min_length=1, description="Object selectors.")
    density: float = Field(gt=0, description="Density [kg/m^3], > 0.")
    label: Optional[str] = Field(default=None, description="Material name for reports.")


class Axis(BaseModel):
    """A rotation axis: a line object of the scene, or two points [m]."""

    model_config = _STRICT
    object: Optional[Selector] = Field(default=None, description="A line object.")
    start: Optional[Point3] = Field(default=None, description="First point [m].")
    end: Optional[Point3] = Field(default=None, description="Second point [m].")

    @model_validator(mode="after")
    def _one_form(self) -> "Axis":
        by_points = self.start is not None or self.end is not None
        if (self.object is None) == (not by_points):
            raise ValueError("give either 'object' or both 'start' and 'end'")
        if by_points:
            if self.start is None or self.end is None:
                raise ValueError("give both 'start' and 'end'")
            _point(self.start, "start")
            _point(self.end, "end")
        return self


class Crack(BaseModel):
    """A crack plane that cuts off the collapsing part.

    ``keep`` is ``"axis_side"`` (default: keep the part that contains the rotation axis),
    ``"positive"`` or ``"negative"`` (the side the plane normal points to, or the other).
    ``keep_point`` names a point on the side to keep instead, which needs no knowledge of
    the plane's normal (in the spec's ``units``). ``objects`` limits the crack to some of the
    body's objects (a crack through one return wall that must not cut the other); by
    default it cuts every object of the body.
    """

    model_config = _STRICT
    object: Optional[Selector] = Field(default=None, description="A planar object.")
    points: Optional[List[Point3]] = Field(default=None, description="Three points [m].")
    keep: Literal["axis_side", "positive", "negative"] = "axis_side"
    keep_point: Optional[Point3] = Field(
        default=None, description="A point on the side of the crack to keep [m]."
    )
    objects: Optional[List[Selector]] = Field(
        default=None,
        min_length=1,
        description="Cut only these objects of the body (default: every object).",
    )

    @field_validator("objects")
    @classmethod
    def _check_objects(cls, value: Optional[List[Selector]]) -> Optional[List[Selector]]:
        return value if value is None else _once(value)

    @model_validator(mode="after")
    def _one_form(self) -> "Crack":
        if (self.object is None) == (self.points is None):
            raise ValueError("give either 'object' or 'points' (three points)")
        if self.keep_point is not None:
            _point(self.keep_point, "keep_point")
            if "keep" in self.model_fields_set:
                raise ValueError("give either 'keep' or 'keep_point', not both")
        if self.points is not None:
            if len(self.points) != 3:
                raise ValueError(f"'points' needs exactly 3 points, got {len(self.points)}")
            for k, p in enumerate(self.points):
                _point(p, f"points[{k}]")
        return self


class _Slab(_Weighed):
    """Objects of one density whose weight and inertia the wall carries a share of."""

    objects: List[Selector] = Field(min_length=1)
    density: float = Field(gt=0, description="Density [kg/m^3], > 0.")
    tributary: float = Field(
        default=TRIBUTARY_DEFAULT, gt=0, le=1, description="Share carried by the wall."
    )


class Floor(_Slab):
    """A floor: classified load-bearing or not from how it meets the wall.

    ``tributary`` is the share of its weight and inertia the wall carries (0.5: a floor
    spanning between the wall and one parallel support).
    """


class Roof(_Slab):
    """A pitched roof: weight share on the wall and thrust from its bounding box (§5)."""

    tied: bool = Field(default=False, description="Tied truss (no thrust on the wall).")


class Vault(BaseModel):
    """A vault springing from the wall: thrusts from the thrust table (§5)."""

    model_config = _STRICT
    objects: List[Selector] = Field(min_length=1)
    construction_class: Literal["a", "b", "c", "d", "e"] = Field(
        description="Ungewitter construction class a-e (see the thrust table)."
    )


class Overburden(_Weighed):
    """What loads the top of a two-block wall: objects (weight share) or a given force [N].

    With ``objects``, N is ``tributary`` times their weight; ``tributary`` defaults to 0.5
    (a slab spanning between the wall and one parallel support), and the output says when
    that default was used.
    """

    objects: Optional[List[Selector]] = Field(default=None, min_length=1)
    density: Optional[float] = Field(default=None, gt=0, description="Density [kg/m^3].")
    tributary: float = Field(
        default=TRIBUTARY_DEFAULT, gt=0, le=1, description="Share carried by the wall."
    )
    force: Optional[float] = Field(default=None, ge=0, description="Given overburden N [N].")

    @field_validator("force")
    @classmethod
    def _check_force(cls, value: Optional[float]) -> Optional[float]:
        return _in_range(value, "force", zero=True)

    @model_validator(mode="after")
    def _one_form(self) -> "Overburden":
        if (self.force is None) == (self.objects is None):
            raise ValueError("give either 'objects' (with 'density') or 'force'")
        if self.objects is not None and self.density is None:
            raise ValueError("'objects' need a 'density'")
        return self


class TieBar(BaseModel):
    """A tie-bar: a line object ending on the façade, and its force [N] (> 0, restraining)."""

    model_config = _STRICT
    object: Selector
    force: float = Field(gt=0, description="Tie force [N], > 0; it restrains the wall.")

    @field_validator("force")
    @classmethod
    def _check_force(cls, value: Optional[float]) -> Optional[float]:
        return _in_range(value, "force")


#: A hinge: a point [x, y, z] in metres, or a line object (its mid-point; its direction is
#: the hinge axis).
Hinge = Union[Point3, Selector]


class Hinges(BaseModel):
    """The four hinges of a three-block mechanism (theory §2.4).

    A and D are on the ground; block 1 joins A and B, block 2 B and C, block 3 D and C.
    """

    model_config = _STRICT
    A: Hinge
    B: Hinge
    C: Hinge
    D: Hinge

    @field_validator("A", "B", "C", "D")
    @classmethod
    def _check_point(cls, value: Hinge, info: ValidationInfo) -> Hinge:
        if isinstance(value, list):
            _point(value, str(info.field_name))
        return value


class MechanismSpec(BaseModel):
    """One mechanism: its objects, axis, cracks and added elements.

    Attributes
    ----------
    id, name : str
        Identifier and description.
    typology : {"single_block", "single_block_loaded"}
        Plain block (A1) or wall with added masses and forces (A2).
    rocking : {"two_sided", "one_sided"}
        Rocking kind.
    groups : list of DensityGroup
        The body: one group per density.
    axis : Axis
        Rotation axis for positive rotation (the collapse direction).
    axis_negative : Axis, optional
        Axis of the other rocking side (two-sided ``single_block``); derived from the base
        footprint if absent. Refused for ``two_block``, whose negative hinges are the mirror
        of O, C, H about the wall's mid-plane.
    hinges, hinges_negative : Hinges, optional
        ``multi_block``: the four hinges of the positive set and of the negative set. The
        negative set is optional for two-sided rocking: when absent it is derived (each
        hinge reflected across its column at its height) and a warning gives the points.
    allow_non_horizontal_axis : bool
        Accept an inclined axis (off by default).
    cracks : list of Crack
        Planes cutting off the collapsing part.
    eta : float, optional
        Coefficient of restitution given by the user (overrides the rules).
    eta_rule : str, optional
        One-sided rule: "one_sided_eq26" (default), "one_sided_alt", "one_sided_energy".
    amplification : Amplification, optional
        Passed through to the constants file.
    floors, roof, vaults, tie_bars
        Added elements (``single_block_loaded`` only); declare only those that exist.
    hinge_height : float, optional
        ``two_block``: the intermediate hinge's height above the base (default Eq. 17).
    """

    model_config = _STRICT
    id: str = Field(min_length=1)
    name: Optional[str] = None
    typology: Literal["single_block", "single_block_loaded", "two_block", "multi_block"] = (
        "single_block"
    )
    rocking: Literal["two_sided", "one_sided"] = "two_sided"
    groups: Optional[List[DensityGroup]] = Field(default=None, min_length=1)
    axis: Optional[Axis] = None
    blocks: Optional[List[List[DensityGroup]]] = Field(
        default=None, min_length=3, max_length=3, description="multi_block: three blocks."
    )
    hinges: Optional[Hinges] = None
    hinges_negative: Optional[Hinges] = None
    axis_negative: Optional[Axis] = None
    allow_non_horizontal_axis: bool = False
    cracks: List[Crack] = Field(default_factory=list)
    eta: Optional[float] = Field(default=None, ge=-1, le=1)
    eta_rule: Optional[Literal["one_sided_eq26", "one_sided_alt", "one_sided_energy"]] = None
    amplification: Optional[Amplification] = None
    floors: Optional[List[Floor]] = None
    roof: Optional[Roof] = None
    vaults: Optional[List[Vault]] = None
    tie_bars: Optional[List[TieBar]] = None
    overburden: Optional[Overburden] = None
    f_mt: Optional[float] = Field(
        default=None, ge=0, description="Mortar tensile strength [Pa] (two_block; default 0)."
    )
    hinge_height: Optional[float] = Field(
        default=None,
        gt=0,
        description="two_block: height of the intermediate hinge above the base, in the spec's "
        "units (default: Eq. 17 from the overburden and f_mt).",
    )
    eccentricity: Optional[Literal["static_moment", "potential"]] = Field(
        default=None,
        description="Eccentric overburden (two_block): as a static moment (the method, "
        "default) or exactly inside the potential.",
    )

    @field_validator("f_mt")
    @classmethod
    def _check_f_mt(cls, value: Optional[float]) -> Optional[float]:
        return _in_range(value, "tensile_strength", zero=True)

    @field_validator("id", "name")
    @classmethod
    def _check_printable(cls, value: Optional[str]) -> Optional[str]:
        # issue #25: the id becomes the constants file's (printable text, as it checks)
        bad = None if value is None else control_character(value)
        if bad is not None:
            raise ValueError(f"must be printable text, got the control character {bad}")
        return value

    @model_validator(mode="after")
    def _consistent(self) -> "MechanismSpec":
        if self.typology == "multi_block":
            if self.blocks is None or self.hinges is None:
                raise ValueError("a multi_block mechanism needs 'blocks' (three) and 'hinges'")
            if self.groups is not None or self.axis is not None or self.cracks:
                raise ValueError(
                    "a multi_block mechanism takes 'blocks' and 'hinges', not "
                    "'groups', 'axis' or 'cracks'"
                )
            if self.rocking == "one_sided" and self.hinges_negative is not None:
                raise ValueError("hinges_negative applies to two-sided rocking only")
        else:
            if self.groups is None or self.axis is None:
                raise ValueError(f"a {self.typology} mechanism needs 'groups' and 'axis'")
            if self.blocks is not None or self.hinges is not None:
                raise ValueError("'blocks' and 'hinges' need typology 'multi_block'")
        added = [k for k in ("floors", "roof", "vaults", "tie_bars") if getattr(self, k)]
        if added and self.typology != "single_block_loaded":
            raise ValueError(
                f"added elements ({', '.join(added)}) need typology 'single_block_loaded'"
            )
        if self.eta is not None:
            problem = eta_problem(self.eta, self.rocking == "one_sided")
            if problem is not None:
                raise ValueError(f"eta {problem}")
        two = [
            k
            for k in ("overburden", "f_mt", "eccentricity", "hinge_height")
            if getattr(self, k) is not None
        ]
        if two and self.typology != "two_block":
            raise ValueError(f"{', '.join(two)} need typology 'two_block'")
        if self.typology == "two_block" and self.cracks:
            raise ValueError("a two-block wall is split at the hinge height; give no cracks")
        if self.hinge_height is not None and self.f_mt:
            raise ValueError(
                "give either 'f_mt' (the hinge height then follows Eq. 17) or 'hinge_height', "
                "not both"
            )
        if self.eta_rule is not None and self.rocking != "one_sided":
            raise ValueError("eta_rule applies to one-sided rocking only")
        if self.axis_negative is not None and self.rocking == "one_sided":
            raise ValueError("axis_negative applies to two-sided rocking only")
        body = [(f"groups[{k}]", g) for k, g in enumerate(self.groups or [])]
        for b, block in enumerate(self.blocks or []):
            body += [(f"blocks[{b}][{k}]", g) for k, g in enumerate(block)]
        first: List[Any] = []  # (selector, group path), in spec order
        for path, group in body:
            for sel in group.objects:
                earlier = [p for s, p in first if s == sel]
                if earlier:
                    raise ValueError(
                        f"{sel!r} is listed in two density groups, {earlier[0]} and {path}; it "
                        "would be counted twice (its mass, I0 and Q doubled): list each object "
                        "in one group"
                    )
                first.append((sel, path))
        if self.axis_negative is not None and self.typology == "two_block":
            raise ValueError(
                "axis_negative does not apply to a two_block wall: its negative hinges O', C', "
                "H' are always the mirror of O, C, H about the wall's mid-plane (base inner "
                "edge, outer face at h_c, top inner edge)"
            )
        return self

    def plausibility_notes(self) -> List[str]:
        """Warnings for admissible but implausible inputs (``rules.QUANTITY_RANGES``).

        Each names the field (``W1.groups[0].density``) and what the value most likely
        means; the builders add them to the mechanism's warnings.
        """
        values: List[Any] = []
        for k, g in enumerate(self.groups or []):
            values.append((g.density, "density", f"groups[{k}].density"))
        for b, block in enumerate(self.blocks or []):
            for k, g in enumerate(block):
                values.append((g.density, "density", f"blocks[{b}][{k}].density"))
        for k, fl in enumerate(self.floors or []):
            values.append((fl.density, "density", f"floors[{k}].density"))
        if self.roof is not None:
            values.append((self.roof.density, "density", "roof.density"))
        for k, tie in enumerate(self.tie_bars or []):
            values.append((tie.force, "force", f"tie_bars[{k}].force"))
        ob = self.overburden
        if ob is not None and ob.density is not None:
            values.append((ob.density, "density", "overburden.density"))
        if ob is not None and ob.force:
            values.append((ob.force, "force", "overburden.force"))
        if self.f_mt:
            values.append((self.f_mt, "tensile_strength", "f_mt"))
        notes = [quantity_note(v, kind, f"{self.id}.{name}") for v, kind, name in values]
        return [n for n in notes if n is not None]


class SpecFile(BaseModel):
    """A mechanism-spec file: version, units of its points and mechanisms (ids unique).

    ``spec_version`` is one of ``SPEC_VERSIONS``; a file without it is read as the current
    version, ``SPEC_VERSION``, and any other version is refused.

    ``units`` says in which unit the points written in the spec (axis ``start``/``end``,
    crack ``points``, hinge points) are: ``"m"`` (the default when absent), ``"cm"``,
    ``"mm"``, or ``"file"`` for the scene file's model units. Objects of the scene are
    always converted from the file's units.
    """

    model_config = _STRICT
    spec_version: str = SPEC_VERSION
    units: Optional[Literal["m", "cm", "mm", "file"]] = Field(
        default=None,
        description="Unit of the points written in the spec: m (default), cm, mm, or 'file' "
        "for the scene file's model units.",
    )
    thrust_table: Optional[str] = Field(
        default=None, description="Path of a user thrust table (JSON), relative to the spec."
    )
    rockmech_version: Optional[str] = Field(
        default=None,
        max_length=100,
        description="Version of rockmech that wrote the file (informative; rockmech fills it "
        "in whenever it writes one, e.g. the specs of `rockmech search`).",
    )
    mechanisms: List[MechanismSpec] = Field(min_length=1)

    @field_validator("spec_version")
    @classmethod
    def _known_version(cls, version: str) -> str:
        if version not in SPEC_VERSIONS:
            raise ValueError(
                f"unknown spec_version {version!r}; this rockmech reads spec_version "
                f"{', '.join(repr(v) for v in SPEC_VERSIONS)} (omit it for the current, "
                f"{SPEC_VERSION!r})"
            )
        return version

    @field_validator("mechanisms")
    @classmethod
    def _unique_ids(cls, mechs: List[MechanismSpec]) -> List[MechanismSpec]:
        seen = set()
        for m in mechs:
            if m.id in seen:
                raise ValueError(f"duplicate mechanism id {m.id!r}")
            seen.add(m.id)
        return mechs


def parse_spec(text: Union[str, bytes], source: str = "spec") -> SpecFile:
    """Validate a spec file's JSON text; errors name the mechanism and the field.

    Every error is reported at once, one per line, so that one bad mechanism does not hide
    the others.

    Raises
    ------
    InputError
        With a message like ``spec.json: mechanisms[0] (id 'W1').groups[0].density: ...``
        (one line per error).
    """
    try:
        return SpecFile.model_validate_json(text)
    except ValidationError as exc:
        data: Any = None
        try:
            data = json.loads(text)
        except (ValueError, RecursionError):  # pydantic has named the error; a deep nest too
            pass
        lines = [f"{path}: {msg}" if path else msg for path, msg in validation_lines(exc, data)]
        raise InputError("\n".join(lines), source) from None
