"""The mechanism spec: which objects of a scene form each mechanism, and how.

A spec file says, per mechanism, which objects (by name, layer or id) form its density
groups, where the rotation axis is, which cracks cut off the collapsing part, the rocking
kind, and the added elements that exist: floors, roof, vaults and tie-bars. Only declared
elements are computed; absent sections stay absent in every output. Unknown keys are
errors. Lengths are in metres once the scene is read (file units are converted); points
written in the spec are in metres unless the file's ``units`` says otherwise (``"file"``:
the scene's model units). Densities are in kg/m³, forces in N.

Each typology has its own model with only its own keys (``TYPOLOGY_SPECS``); a mechanism is
read by the model its ``typology`` names (``MechanismSpec``, a union keyed on ``typology``),
and every list of typologies (``TYPOLOGIES``, the constants file's, the JSON Schemas, the
builders and the Rhino commands) follows from these models.

Python 3.9-clean: imported by Rhino 8.
"""

import json
from typing import (
    TYPE_CHECKING,
    Annotated,
    Any,
    ClassVar,
    Dict,
    List,
    Literal,
    Optional,
    Sequence,
    Tuple,
    Type,
    Union,
    get_args,
)

from pydantic import (
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    Tag,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from shared_schema.errors import InputError
from shared_schema.rules import (
    control_character,
    coordinate_problem,
    eta_problem,
    quantity_note,
    quantity_problem,
)
from shared_schema.validation import validation_lines

__all__ = [
    "DEFAULT_TYPOLOGY",
    "SPEC_VERSION",
    "SPEC_VERSIONS",
    "TRIBUTARY_DEFAULT",
    "TYPOLOGIES",
    "TYPOLOGY_SPECS",
    "Amplification",
    "Axis",
    "Crack",
    "DensityGroup",
    "Floor",
    "Hinges",
    "LoadedWallSpec",
    "MechanismBase",
    "MechanismSpec",
    "MultiBlockSpec",
    "Overburden",
    "Roof",
    "SingleBlockSpec",
    "SpecFile",
    "TieBar",
    "TwoBlockSpec",
    "Vault",
    "mechanism_union",
    "parse_spec",
    "typology_of",
]

#: Format version of spec files written today; a file without ``spec_version`` is read as it.
SPEC_VERSION = "1.0"
#: Versions this reader understands; any other is refused (a newer file may mean other things).
SPEC_VERSIONS = ("1.0",)
#: Share of a floor's, roof's or overburden's weight and inertia a wall carries when the spec
#: does not say (a slab spanning between the wall and one parallel support); stated in a
#: warning whenever it is used.
TRIBUTARY_DEFAULT = 0.5

#: The spec's models (not ``Amplification``, which the constants file holds) build their
#: validators on first use: the constants file's models, and so a pulse, import this module
#: for ``Amplification`` and ``TYPOLOGIES`` and need none of them (#38).
_STRICT = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False, defer_build=True)

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


class Amplification(BaseModel):
    """Data for amplifying the ground motion up the structure (theory §7, Eqs. 27-28).

    Written in a spec and passed through to the kinematic-constants file
    (``shared_schema.constants``).

    Attributes
    ----------
    f_n : float
        Natural frequency of the supporting structure [Hz], > 0.
    h_e : float
        Effective (modal) height of the supporting structure, ``sum(m h^2)/sum(m h)`` [m], > 0.
    h : float
        Height of the mechanism's base above the ground [m], >= 0.
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={
            "description": "Data for amplifying the ground motion up the structure (theory §7)."
        },
    )

    f_n: float = Field(gt=0, description="Natural frequency of the supporting structure [Hz], > 0.")
    h_e: float = Field(
        gt=0,
        description="Effective (modal) height of the supporting structure [m], > 0.",
    )
    h: float = Field(ge=0, description="Height of the mechanism's base above the ground [m], >= 0.")


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
    that default was used. ``xi`` places N at ``xi b`` from the top hinge H of the positive
    side (theory §2.3; a search spec measures it from the wall's outer face); without it a
    force acts on the wall's centre line (``xi = 0.5``) and objects at the centroid of their
    contact with the wall's top.
    """

    objects: Optional[List[Selector]] = Field(default=None, min_length=1)
    density: Optional[float] = Field(default=None, gt=0, description="Density [kg/m^3].")
    tributary: float = Field(
        default=TRIBUTARY_DEFAULT, gt=0, le=1, description="Share carried by the wall."
    )
    force: Optional[float] = Field(default=None, ge=0, description="Given overburden N [N].")
    xi: Optional[float] = Field(
        default=None,
        ge=0,
        le=1,
        description="Where N acts: at xi b from the top hinge H of the positive side (theory "
        "2.3; in a search spec, from the wall's outer face), b the thickness; default: the "
        "centre line for a force, the objects' contact for objects.",
    )

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


def _either(names: Sequence[str]) -> str:
    """Return the names quoted and joined: ``'a'``, ``'a' or 'b'``, ``'a', 'b' or 'c'``."""
    quoted = [repr(n) for n in names]
    return quoted[0] if len(quoted) == 1 else f"{', '.join(quoted[:-1])} or {quoted[-1]}"


def _empty(value: Any) -> bool:
    """Tell whether a spec value says nothing: null, false or an empty list."""
    return value is None or value is False or (isinstance(value, list) and not value)


class MechanismBase(BaseModel):
    """What every mechanism of a spec has, whatever its typology.

    Each typology is a subclass (its own fields and checks) listed in ``TYPOLOGY_SPECS``;
    ``MechanismSpec`` tells them apart by ``typology``.

    Attributes
    ----------
    id, name : str
        Identifier and description.
    typology : str
        The typology (each subclass narrows it to its own name).
    rocking : {"two_sided", "one_sided"}
        Rocking kind.
    eta : float, optional
        Coefficient of restitution given by the user (overrides the rules).
    eta_rule : str, optional
        One-sided rule: "one_sided_eq26" (default), "one_sided_alt", "one_sided_energy".
    amplification : Amplification, optional
        Passed through to the constants file.
    """

    model_config = _STRICT
    #: Keys of other typologies this one refuses with its own reason (key -> reason); any
    #: other key of another typology is refused naming the typologies that take it.
    REFUSED: ClassVar[Dict[str, str]] = {}

    id: str = Field(min_length=1)
    name: Optional[str] = None
    typology: str
    rocking: Literal["two_sided", "one_sided"] = "two_sided"
    eta: Optional[float] = Field(default=None, ge=-1, le=1)
    eta_rule: Optional[Literal["one_sided_eq26", "one_sided_alt", "one_sided_energy"]] = None
    amplification: Optional[Amplification] = None

    @model_validator(mode="before")
    @classmethod
    def _own_keys(cls, data: Any) -> Any:
        """Refuse a key of another typology, saying which typology takes it.

        A key of another typology left empty (null, [] or false: what a writer of every
        field puts there) says nothing and is read as absent, as the files have always been.
        """
        if not isinstance(data, dict):
            return data
        others = [k for k in data if isinstance(k, str) and k not in cls.model_fields]
        known = {k for m in TYPOLOGY_SPECS for k in m.model_fields}
        empty = [k for k in others if k in known and _empty(data[k])]
        if empty:
            data = {k: v for k, v in data.items() if k not in empty}
        foreign = [k for k in others if k not in empty]
        for key in foreign:
            if key in cls.REFUSED:
                raise ValueError(cls.REFUSED[key])
        owners: Dict[str, List[str]] = {}
        for key in foreign:
            takers = [typology_of(m) for m in TYPOLOGY_SPECS if key in m.model_fields]
            if takers:  # a key no typology takes is an unknown key (extra="forbid")
                owners.setdefault(_either(takers), []).append(key)
        if owners:
            raise ValueError(
                "; ".join(
                    f"{_either(keys)} {'needs' if len(keys) == 1 else 'need'} typology {who}"
                    for who, keys in owners.items()
                )
            )
        return data

    @field_validator("id", "name")
    @classmethod
    def _check_printable(cls, value: Optional[str]) -> Optional[str]:
        # issue #25: the id becomes the constants file's (printable text, as it checks)
        bad = None if value is None else control_character(value)
        if bad is not None:
            raise ValueError(f"must be printable text, got the control character {bad}")
        return value

    @model_validator(mode="after")
    def _consistent(self) -> "MechanismBase":
        if self.eta is not None:
            problem = eta_problem(self.eta, self.rocking == "one_sided")
            if problem is not None:
                raise ValueError(f"eta {problem}")
        if self.eta_rule is not None and self.rocking != "one_sided":
            raise ValueError("eta_rule applies to one-sided rocking only")
        first: List[Any] = []  # (selector, group path), in spec order
        for path, group in self.body_groups():
            for sel in group.objects:
                earlier = [p for s, p in first if s == sel]
                if earlier:
                    raise ValueError(
                        f"{sel!r} is listed in two density groups, {earlier[0]} and {path}; it "
                        "would be counted twice (its mass, I0 and Q doubled): list each object "
                        "in one group"
                    )
                first.append((sel, path))
        return self

    def body_groups(self) -> List[Tuple[str, DensityGroup]]:
        """Return the density groups of the moving body, each with its path in the spec."""
        return []

    def quantities(self) -> List[Tuple[float, str, str]]:
        """``(value, kind, path)`` of the physical inputs ``rules.QUANTITY_RANGES`` bounds."""
        return [(g.density, "density", f"{path}.density") for path, g in self.body_groups()]

    def plausibility_notes(self) -> List[str]:
        """Warnings for admissible but implausible inputs (``rules.QUANTITY_RANGES``).

        Each names the field (``W1.groups[0].density``) and what the value most likely
        means; the builders add them to the mechanism's warnings.
        """
        notes = [quantity_note(v, kind, f"{self.id}.{name}") for v, kind, name in self.quantities()]
        return [n for n in notes if n is not None]


class _Walled(MechanismBase):
    """A body of density groups turning about an axis (single, loaded and two-block walls).

    Attributes
    ----------
    groups : list of DensityGroup
        The body: one group per density.
    axis : Axis
        Rotation axis for positive rotation (the collapse direction).
    allow_non_horizontal_axis : bool
        Accept an inclined axis (off by default).
    """

    groups: List[DensityGroup] = Field(min_length=1)
    axis: Axis
    allow_non_horizontal_axis: bool = False

    def body_groups(self) -> List[Tuple[str, DensityGroup]]:
        return [(f"groups[{k}]", g) for k, g in enumerate(self.groups)]


class _Cut(_Walled):
    """A body cut off by cracks, rocking about its axis or, two-sided, about a second one.

    Attributes
    ----------
    axis_negative : Axis, optional
        Axis of the other rocking side (two-sided); derived from the base footprint if absent.
    cracks : list of Crack
        Planes cutting off the collapsing part.
    """

    axis_negative: Optional[Axis] = None
    cracks: List[Crack] = Field(default_factory=list)

    @model_validator(mode="after")
    def _one_axis_one_sided(self) -> "_Cut":
        if self.axis_negative is not None and self.rocking == "one_sided":
            raise ValueError("axis_negative applies to two-sided rocking only")
        return self


class SingleBlockSpec(_Cut):
    """A single rocking block (A1, docs/theory.md §2.1); the typology of a spec that names none."""

    typology: Literal["single_block"] = "single_block"


class LoadedWallSpec(_Cut):
    """A wall with added masses and forces (A2, docs/theory.md §2.2).

    Attributes
    ----------
    floors, roof, vaults, tie_bars
        The added elements; declare only those that exist.
    """

    typology: Literal["single_block_loaded"]
    floors: Optional[List[Floor]] = None
    roof: Optional[Roof] = None
    vaults: Optional[List[Vault]] = None
    tie_bars: Optional[List[TieBar]] = None

    def quantities(self) -> List[Tuple[float, str, str]]:
        """Return the body's densities and the added elements' densities and forces."""
        values = super().quantities()
        for k, fl in enumerate(self.floors or []):
            values.append((fl.density, "density", f"floors[{k}].density"))
        if self.roof is not None:
            values.append((self.roof.density, "density", "roof.density"))
        for k, tie in enumerate(self.tie_bars or []):
            values.append((tie.force, "force", f"tie_bars[{k}].force"))
        return values


class TwoBlockSpec(_Walled):
    """A wall restrained top and bottom that folds about an intermediate hinge (A3, §2.3).

    Attributes
    ----------
    overburden : Overburden, optional
        What loads the top of the wall.
    f_mt : float, optional
        Mortar tensile strength [Pa] (default 0).
    hinge_height : float, optional
        Height of the intermediate hinge above the base (default Eq. 17).
    eccentricity : {"static_moment", "potential"}, optional
        How an eccentric overburden enters.
    """

    REFUSED: ClassVar[Dict[str, str]] = {
        "cracks": "a two-block wall is split at the hinge height; give no cracks",
        "axis_negative": "axis_negative does not apply to a two_block wall: its negative hinges "
        "O', C', H' are always the mirror of O, C, H about the wall's mid-plane (base inner "
        "edge, outer face at h_c, top inner edge)",
    }

    typology: Literal["two_block"]
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

    @model_validator(mode="after")
    def _one_hinge_rule(self) -> "TwoBlockSpec":
        if self.hinge_height is not None and self.f_mt:
            raise ValueError(
                "give either 'f_mt' (the hinge height then follows Eq. 17) or 'hinge_height', "
                "not both"
            )
        return self

    def quantities(self) -> List[Tuple[float, str, str]]:
        """Return the body's densities, the overburden's density or force, and f_mt."""
        values = super().quantities()
        ob = self.overburden
        if ob is not None and ob.density is not None:
            values.append((ob.density, "density", "overburden.density"))
        if ob is not None and ob.force:
            values.append((ob.force, "force", "overburden.force"))
        if self.f_mt:
            values.append((self.f_mt, "tensile_strength", "f_mt"))
        return values


class MultiBlockSpec(MechanismBase):
    """Three blocks joined by four hinges (A4, docs/theory.md §2.4).

    Attributes
    ----------
    blocks : list of three lists of DensityGroup
        Block 1 (AB), block 2 (BC), block 3 (DC).
    hinges, hinges_negative : Hinges
        The four hinges of the positive set and, optionally, of the negative set. The
        negative set is optional for two-sided rocking: when absent it is derived (each
        hinge reflected across its column at its height) and a warning gives the points.
    """

    REFUSED: ClassVar[Dict[str, str]] = {
        key: "a multi_block mechanism needs 'blocks' (three) and 'hinges', not 'groups', "
        "'axis' or 'cracks'"
        for key in ("groups", "axis", "cracks")
    }

    typology: Literal["multi_block"]
    blocks: List[List[DensityGroup]] = Field(
        min_length=3, max_length=3, description="multi_block: three blocks."
    )
    hinges: Hinges
    hinges_negative: Optional[Hinges] = None

    @model_validator(mode="after")
    def _negative_two_sided(self) -> "MultiBlockSpec":
        if self.rocking == "one_sided" and self.hinges_negative is not None:
            raise ValueError("hinges_negative applies to two-sided rocking only")
        return self

    def body_groups(self) -> List[Tuple[str, DensityGroup]]:
        """Return the density groups of the three blocks, each with its path."""
        return [
            (f"blocks[{b}][{k}]", g)
            for b, block in enumerate(self.blocks)
            for k, g in enumerate(block)
        ]


def typology_of(model: Type[MechanismBase]) -> str:
    """Return the typology a spec model stands for: its ``typology`` literal."""
    names = get_args(model.model_fields["typology"].annotation)
    if len(names) != 1:
        raise TypeError(f"{model.__name__}.typology must be one Literal name, got {names!r}")
    return str(names[0])


#: One spec model per typology, in the order every list of typologies follows. A new
#: typology is its model (a ``MechanismBase`` with its own ``typology`` literal) and one
#: entry here; its builder goes in ``cad_maths.mechanisms.build.MECHANISMS``.
TYPOLOGY_SPECS: Tuple[Type[MechanismBase], ...] = (
    SingleBlockSpec,
    LoadedWallSpec,
    TwoBlockSpec,
    MultiBlockSpec,
)
#: Mechanism typologies a spec can ask for (constants files also take ``user_defined``).
TYPOLOGIES: Tuple[str, ...] = tuple(typology_of(m) for m in TYPOLOGY_SPECS)
#: The typology of a mechanism that names none: the first, whose model alone has a default.
DEFAULT_TYPOLOGY = TYPOLOGIES[0]


def _typology_tag(value: Any) -> Optional[str]:
    """Return the union's tag of a mechanism: its ``typology`` (default ``single_block``)."""
    if isinstance(value, dict):
        tag = value.get("typology", DEFAULT_TYPOLOGY)
        return tag if isinstance(tag, str) else None
    if isinstance(value, MechanismBase):
        return value.typology
    return DEFAULT_TYPOLOGY  # not an object: the default model says so ("should be an object")


def mechanism_union(models: Sequence[Type[MechanismBase]]) -> Any:
    """Return the pydantic type of a spec's mechanism: one of ``models``, by ``typology``."""
    choices = tuple(Annotated[m, Tag(typology_of(m))] for m in models)
    return Annotated[Union[choices], Discriminator(_typology_tag)]


if TYPE_CHECKING:
    #: Any typology's spec model (``TYPOLOGY_SPECS``).
    MechanismSpec = MechanismBase
else:
    MechanismSpec = mechanism_union(TYPOLOGY_SPECS)


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
        errors = [_plain_error(err) for err in exc.errors(include_url=False)]
        lines = [f"{path}: {msg}" if path else msg for path, msg in validation_lines(errors, data)]
        raise InputError("\n".join(lines), source) from None


def _plain_error(err: Any) -> Any:
    """Return a pydantic error of a spec as the flat model of the file reads it.

    The union of typologies puts its tag in the path (``mechanisms.0.two_block.f_mt``): the
    tag is left out, since the mechanism's own ``typology`` says it. A typology no model
    takes is an error of the field ``typology`` listing the typologies.
    """
    loc = tuple(err["loc"])
    if len(loc) >= 2 and loc[0] == "mechanisms" and isinstance(loc[1], int):
        if err["type"] in ("union_tag_invalid", "union_tag_not_found") and len(loc) == 2:
            return dict(err, loc=(*loc, "typology"), msg=f"Input should be {_either(TYPOLOGIES)}")
        if len(loc) >= 3 and loc[2] in TYPOLOGIES:
            return dict(err, loc=loc[:2] + loc[3:])
    return err
