"""Prompt flows of the mechanism commands, and the runner that writes their two files.

Each flow asks a :class:`~rhino_plugin.flows.prompter.Prompter` for what the method needs
(objects per density, axis, cracks, added elements, hinges) and returns one mechanism of a
spec file (``shared_schema.spec``), objects named by their name when it is unique in the
scene and by id otherwise. :func:`run_mechanism_command` validates the spec, computes the
kinematic constants with the same code as ``rockmech constants`` and only then writes
``<stem>.spec.json`` and ``<stem>.constants.json`` (atomically), so a cancelled or failed
command leaves no file behind.

Answers are checked as they come: an empty selection, a selected object that is not a
closed solid (or not a line, or not planar), an unknown object id and a density that is not
a positive number are :class:`~shared_schema.errors.InputError` /
:class:`~shared_schema.errors.GeometryError` naming the field or the object.

Units: densities [kg/m³], forces [N], f_mt [Pa], f_n [Hz], heights [m]; picked and drawn
points arrive in model units and are converted to metres with the scene's unit scale.

Python 3.9-clean: imported by Rhino 8.
"""

import json
import os
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Type

from cad_maths.mechanisms.build import constants_from_spec
from rhino_plugin.flows.marks import check_marks
from rhino_plugin.flows.prompter import Cancelled, Point, Prompter
from shared_schema.atomic import write_atomic
from shared_schema.errors import InputError, RockmechError
from shared_schema.io import write_constants
from shared_schema.rules import check_number, quantity_problem
from shared_schema.spec import (
    TRIBUTARY_DEFAULT,
    LoadedWallSpec,
    MechanismBase,
    MultiBlockSpec,
    SingleBlockSpec,
    TwoBlockSpec,
    parse_spec,
    typology_of,
)

__all__ = [
    "COMMANDS",
    "FLOWS",
    "MECHANISM_COMMANDS",
    "CommandResult",
    "MechanismCommand",
    "loaded_wall_flow",
    "multi_block_flow",
    "run_mechanism_command",
    "single_block_flow",
    "spec_selector",
    "two_block_flow",
    "write_outputs",
]

#: Rocking options as shown at the prompt -> spec value.
ROCKING = {"TwoSided": "two_sided", "OneSided": "one_sided"}
#: Crack side options -> spec ``keep``.
KEEP = {"AxisSide": "axis_side", "Positive": "positive", "Negative": "negative"}
#: Added elements offered by the loaded-wall checkbox dialog.
ADDED_ELEMENTS = ("Floors", "Roof", "Vaults", "Tie-bars")
#: Vault construction classes (theory §5, the thrust table).
VAULT_CLASSES = ("a", "b", "c", "d", "e")
#: The three blocks of a multi-block mechanism, in spec order (theory §2.4).
BLOCK_LABELS = ("block 1 (AB, turning about A)", "block 2 (BC)", "block 3 (DC, turning about D)")
HINGE_NAMES = ("A", "B", "C", "D")


def checked_number(
    answer: Any,
    what: str,
    where: str,
    *,
    above: Optional[float] = None,
    at_least: Optional[float] = None,
    at_most: Optional[float] = None,
    kind: Optional[str] = None,
) -> float:
    """Return a prompt's answer as a finite float within bounds, or raise InputError.

    ``kind`` (a key of ``shared_schema.rules.QUANTITY_RANGES``: density, force,
    tensile_strength) also refuses a non-zero value beyond that quantity's admissible range,
    at the prompt, with the rule the spec file obeys.
    """
    if isinstance(answer, bool) or answer is None:
        raise InputError(f"{what} must be a number, got {answer!r}", where)
    try:
        value = float(answer.strip() if isinstance(answer, str) else answer)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number, got {answer!r}", where) from None
    try:
        value = check_number(value, where, above=above, at_least=at_least, at_most=at_most)
    except InputError as err:
        raise InputError(f"{what} {err.reason}", where) from None
    if kind is not None and value != 0.0:
        problem = quantity_problem(value, kind)
        if problem is not None:
            raise InputError(f"{what} {problem}", where)
    return value


def spec_selector(scene: Any, obj: Any) -> Any:
    """Selector of a scene object in a spec: its name if no other object has it, else its id."""
    if obj.name and sum(1 for o in scene.objects if o.name == obj.name) == 1:
        return obj.name
    return {"id": obj.id}


class _Asker:
    """Asks one mechanism's questions and checks every answer against the scene."""

    def __init__(self, prompter: Prompter, scene: Any, mech_id: str) -> None:
        self.prompter = prompter
        self.scene = scene
        self.mech_id = mech_id

    def where(self, path: str) -> str:
        return f"{self.mech_id}.{path}"

    def objects(
        self, prompt: str, kind: str, path: str, *, multiple: bool = True, optional: bool = False
    ) -> List[Any]:
        """Ask for objects of ``kind``; check each and return spec selectors."""
        ids = list(self.prompter.get_objects(prompt, kind, multiple, optional))
        if not ids:
            if optional:
                return []
            raise InputError("nothing was selected", self.where(path))
        if not multiple and len(ids) > 1:
            raise InputError(f"select one object, got {len(ids)}", self.where(path))
        selectors = []
        for ident in ids:
            obj = self.scene.find({"id": str(ident)})[0]
            if kind == "solid":
                self.scene.mesh(obj)  # an open or non-solid object fails here, by name
            elif kind == "line":
                self.scene.line(obj)
            elif kind == "plane":
                self.scene.plane(obj)
            else:
                raise ValueError(f"unknown object kind {kind!r}")
            selectors.append(spec_selector(self.scene, obj))
        return selectors

    def number(
        self, prompt: str, what: str, path: str, default: Optional[float] = None, **bounds: Any
    ) -> float:
        answer = self.prompter.get_number(prompt, default)
        return checked_number(answer, what, self.where(path), **bounds)

    def tributary(self, what: str, path: str) -> float:
        """Ask the share of ``what``'s weight and inertia the wall carries (0.5 offered)."""
        return self.number(
            f"Share of {what} the wall carries (tributary) [-]",
            "the tributary share [-]",
            path,
            default=TRIBUTARY_DEFAULT,
            above=0.0,
            at_most=1.0,
        )

    def carried(self, objects: List[Any], what: str, path: str) -> Dict[str, Any]:
        """Ask the density and the tributary share of ``objects``, which the wall carries.

        For a floor, the roof or the elements carrying the overburden; returns their spec
        entry (``objects``, ``density``, ``tributary``; ``path`` is its place in the spec).
        """
        density = self.number(
            f"Density of {what} [kg/m³]",
            "the density [kg/m³]",
            f"{path}.density",
            above=0.0,
            kind="density",
        )
        share = self.tributary(what, f"{path}.tributary")
        return {"objects": objects, "density": density, "tributary": share}

    def option(self, prompt: str, options: Sequence[str], default: int = 0) -> str:
        answer = self.prompter.get_option(prompt, list(options), default)
        if answer not in options:
            raise InputError(f"expected one of {list(options)}, got {answer!r}", self.mech_id)
        return answer

    def to_m(self, p: Point) -> List[float]:
        if len(p) != 3:
            raise InputError(f"a point needs 3 coordinates, got {p!r}", self.mech_id)
        return [float(c) * self.scene.unit_scale for c in p]

    def groups(self, label: str, path: str, *, first: int = 0) -> List[Dict[str, Any]]:
        """Density groups: objects, then their density, until an empty selection."""
        groups: List[Dict[str, Any]] = []
        while True:
            k = first + len(groups)
            optional = bool(groups) or first > 0
            more = " (Enter when done)" if optional else ""
            sels = self.objects(
                f"Select the {label} objects of density group {len(groups) + 1}{more}",
                "solid",
                f"{path}[{k}].objects",
                optional=optional,
            )
            if not sels:
                return groups
            density = self.number(
                f"Density of group {len(groups) + 1} of the {label} [kg/m³]",
                "the density [kg/m³]",
                f"{path}[{k}].density",
                above=0.0,
                kind="density",
            )
            groups.append({"objects": sels, "density": density})

    def axis(self, prompt: str, path: str) -> Dict[str, Any]:
        """Ask for an axis: a line object, or two drawn points (returned in metres)."""
        answer = self.prompter.get_line(prompt)
        if isinstance(answer, str):
            obj = self.scene.find({"id": answer})[0]
            self.scene.line(obj)
            return {"object": spec_selector(self.scene, obj)}
        start, end = answer
        return {"start": self.to_m(start), "end": self.to_m(end)}

    def hinge(self, prompt: str, path: str) -> Any:
        """Ask for a hinge: a line object, or the mid-point [m] of a drawn line."""
        axis = self.axis(prompt, path)
        if "object" in axis:
            return axis["object"]
        return [0.5 * (a + b) for a, b in zip(axis["start"], axis["end"])]

    def cracks(self, path: str) -> List[Dict[str, Any]]:
        """Cracks, each a planar object or three points, with the side to keep."""
        cracks: List[Dict[str, Any]] = []
        while True:
            how = self.option(
                f"Add crack {len(cracks) + 1}?", ["Done", "PlanarObject", "ThreePoints"], 0
            )
            if how == "Done":
                return cracks
            where = f"{path}[{len(cracks)}]"
            crack: Dict[str, Any]
            if how == "PlanarObject":
                sel = self.objects("Select the crack plane", "plane", where, multiple=False)
                crack = {"object": sel[0]}
            else:
                pts = self.prompter.get_points("Pick three points on the crack plane", 3)
                if len(pts) != 3:
                    raise InputError(f"a crack needs 3 points, got {len(pts)}", self.where(where))
                crack = {"points": [self.to_m(p) for p in pts]}
            keep = self.option("Side to keep", list(KEEP), 0)
            if KEEP[keep] != "axis_side":
                crack["keep"] = KEEP[keep]
            cracks.append(crack)

    def finish(self, mech: Dict[str, Any]) -> Dict[str, Any]:
        """Ask for the optional η override and amplification data (every typology)."""
        if self.option("Coefficient of restitution", ["Computed", "Override"], 0) == "Override":
            lo, hi = (-1.0, 0.0) if mech.get("rocking") == "one_sided" else (0.0, 1.0)
            mech["eta"] = self.number(
                f"Coefficient of restitution eta [{lo:g}, {hi:g}]",
                "eta",
                "eta",
                at_least=lo,
                at_most=hi,
            )
        if self.option("Amplification data (mechanism above ground)", ["No", "Yes"], 0) == "Yes":
            mech["amplification"] = {
                "f_n": self.number(
                    "Natural frequency of the structure f_n [Hz]",
                    "f_n [Hz]",
                    "amplification.f_n",
                    above=0.0,
                ),
                "h_e": self.number(
                    "Effective height of the structure h_e [m]",
                    "h_e [m]",
                    "amplification.h_e",
                    above=0.0,
                ),
                "h": self.number(
                    "Height of the mechanism's base h [m]",
                    "h [m]",
                    "amplification.h",
                    at_least=0.0,
                ),
            }
        return mech


def single_block_flow(prompter: Prompter, scene: Any, mech_id: str) -> Dict[str, Any]:
    """RM_SingleBlock (A1): density groups, axis, cracks, rocking kind, η, amplification."""
    ask = _Asker(prompter, scene, mech_id)
    mech: Dict[str, Any] = {"id": mech_id, "typology": typology_of(SingleBlockSpec)}
    mech["groups"] = ask.groups("block", "groups")
    mech["axis"] = ask.axis("Pick or draw the rotation axis", "axis")
    cracks = ask.cracks("cracks")
    if cracks:
        mech["cracks"] = cracks
    mech["rocking"] = ROCKING[ask.option("Rocking", list(ROCKING), 0)]
    if mech["rocking"] == "two_sided":
        other = ask.option("Axis of the other rocking side", ["FromBase", "PickOrDraw"], 0)
        if other == "PickOrDraw":
            mech["axis_negative"] = ask.axis(
                "Pick or draw the axis of the other rocking side", "axis_negative"
            )
    return ask.finish(mech)


def loaded_wall_flow(prompter: Prompter, scene: Any, mech_id: str) -> Dict[str, Any]:
    """RM_LoadedWall (A2): walls, axis, cracks, then only the ticked added elements."""
    ask = _Asker(prompter, scene, mech_id)
    mech: Dict[str, Any] = {
        "id": mech_id,
        "typology": typology_of(LoadedWallSpec),
        # the added forces act on one side (docs/geometry.md)
        "rocking": "one_sided",
    }
    groups = ask.groups("main wall", "groups")
    groups += ask.groups("adjacent wall", "groups", first=len(groups))
    mech["groups"] = groups
    mech["axis"] = ask.axis("Pick or draw the rotation axis", "axis")
    cracks = ask.cracks("cracks")
    if cracks:
        mech["cracks"] = cracks
    ticked = prompter.get_checkboxes("Added elements of the wall", list(ADDED_ELEMENTS))
    if ticked.get("Floors"):
        floors: List[Dict[str, Any]] = []
        while True:
            k = len(floors)
            sels = ask.objects(
                f"Select floor {k + 1}" + (" (Enter when done)" if floors else ""),
                "solid",
                f"floors[{k}].objects",
                optional=bool(floors),
            )
            if not sels:
                break
            floors.append(ask.carried(sels, f"floor {k + 1}", f"floors[{k}]"))
        mech["floors"] = floors
    if ticked.get("Roof"):
        sels = ask.objects("Select the roof", "solid", "roof.objects")
        roof = ask.carried(sels, "the roof", "roof")
        if ask.option("Roof structure", ["Thrusting", "Tied"], 0) == "Tied":
            roof["tied"] = True
        mech["roof"] = roof
    if ticked.get("Vaults"):
        vaults: List[Dict[str, Any]] = []
        while True:
            k = len(vaults)
            sels = ask.objects(
                f"Select vault {k + 1}" + (" (Enter when done)" if vaults else ""),
                "solid",
                f"vaults[{k}].objects",
                optional=bool(vaults),
            )
            if not sels:
                break
            cls = ask.option(f"Construction class of vault {k + 1}", VAULT_CLASSES, 1)
            vaults.append({"objects": sels, "construction_class": cls})
        mech["vaults"] = vaults
    if ticked.get("Tie-bars"):
        ties: List[Dict[str, Any]] = []
        while True:
            k = len(ties)
            sels = ask.objects(
                f"Select the line of tie-bar {k + 1}" + (" (Enter when done)" if ties else ""),
                "line",
                f"tie_bars[{k}].object",
                multiple=False,
                optional=bool(ties),
            )
            if not sels:
                break
            force = ask.number(
                f"Force of tie-bar {k + 1} [N]",
                "the tie force [N]",
                f"tie_bars[{k}].force",
                above=0.0,
                kind="force",
            )
            ties.append({"object": sels[0], "force": force})
        mech["tie_bars"] = ties
    return ask.finish(mech)


def two_block_flow(prompter: Prompter, scene: Any, mech_id: str) -> Dict[str, Any]:
    """RM_TwoBlock (A3): the wall, its base axis, what carries N, densities and f_mt."""
    ask = _Asker(prompter, scene, mech_id)
    mech: Dict[str, Any] = {"id": mech_id, "typology": typology_of(TwoBlockSpec)}
    mech["groups"] = ask.groups("wall", "groups")
    mech["axis"] = ask.axis("Pick or draw the base axis (outer bottom edge)", "axis")
    source = ask.option("Overburden N from", ["Objects", "Force", "None"], 0)
    if source == "Objects":
        sels = ask.objects("Select the elements carrying N", "solid", "overburden.objects")
        mech["overburden"] = ask.carried(sels, "the elements carrying N", "overburden")
    elif source == "Force":
        mech["overburden"] = {
            "force": ask.number(
                "Overburden N [N]", "N [N]", "overburden.force", at_least=0.0, kind="force"
            )
        }
    f_mt = ask.number(
        "Mortar tensile strength f_mt [Pa]",
        "f_mt [Pa]",
        "f_mt",
        at_least=0.0,
        kind="tensile_strength",
    )
    if f_mt > 0.0:
        mech["f_mt"] = f_mt
    mech["rocking"] = ROCKING[ask.option("Rocking", list(ROCKING), 0)]
    return ask.finish(mech)


def multi_block_flow(prompter: Prompter, scene: Any, mech_id: str) -> Dict[str, Any]:
    """RM_MultiBlock (A4): three object groups and two hinge sets A, B, C, D."""
    ask = _Asker(prompter, scene, mech_id)
    mech: Dict[str, Any] = {"id": mech_id, "typology": typology_of(MultiBlockSpec)}
    mech["rocking"] = ROCKING[ask.option("Rocking", list(ROCKING), 0)]
    mech["blocks"] = [ask.groups(label, f"blocks[{k}]") for k, label in enumerate(BLOCK_LABELS)]
    mech["hinges"] = {
        n: ask.hinge(f"Pick or draw hinge {n} (positive rotation)", f"hinges.{n}")
        for n in HINGE_NAMES
    }
    if mech["rocking"] == "two_sided":
        neg = ask.option("Hinges for negative rotation", ["Mirrored", "PickOrDraw"], 0)
        if neg == "PickOrDraw":
            mech["hinges_negative"] = {
                n: ask.hinge(f"Pick or draw hinge {n} (negative rotation)", f"hinges_negative.{n}")
                for n in HINGE_NAMES
            }
    return ask.finish(mech)


#: A prompt flow: ``(prompter, scene, mechanism id) -> one mechanism of a spec``.
Flow = Callable[[Prompter, Any, str], Dict[str, Any]]


@dataclass(frozen=True)
class MechanismCommand:
    """A Rhino command that asks for one mechanism of a typology.

    Attributes
    ----------
    command : str
        The command's name; its script is ``rhino_plugin/rhino/<command>.py``, listed in
        ``rockmech.rhproj``.
    spec : type
        The typology's spec model (``shared_schema.spec.TYPOLOGY_SPECS``).
    prefix : str
        Prefix of the mechanism ids it proposes (``SB1``, ``SB2``...).
    flow : Flow
        The prompts.
    """

    command: str
    spec: Type[MechanismBase]
    prefix: str
    flow: Flow

    @property
    def typology(self) -> str:
        """The typology's name (the spec model's ``typology`` literal)."""
        return typology_of(self.spec)


#: The mechanism commands, one line per typology.
MECHANISM_COMMANDS = (
    MechanismCommand("RM_SingleBlock", SingleBlockSpec, "SB", single_block_flow),
    MechanismCommand("RM_LoadedWall", LoadedWallSpec, "LW", loaded_wall_flow),
    MechanismCommand("RM_TwoBlock", TwoBlockSpec, "TB", two_block_flow),
    MechanismCommand("RM_MultiBlock", MultiBlockSpec, "MB", multi_block_flow),
)

#: Typology -> flow.
FLOWS: Dict[str, Flow] = {c.typology: c.flow for c in MECHANISM_COMMANDS}

#: Rhino command -> (typology, prefix of its mechanism ids).
COMMANDS: Dict[str, Tuple[str, str]] = {
    c.command: (c.typology, c.prefix) for c in MECHANISM_COMMANDS
}


@dataclass
class CommandResult:
    """What a mechanism command wrote.

    Attributes
    ----------
    spec_path, constants_path : str
        The two files.
    spec : shared_schema.spec.SpecFile
    constants : shared_schema.constants.ConstantsFile
    marks : list of rhino_plugin.flows.marks.Mark
        Axes, centres of mass and hinges to draw for checking [model units].
    messages : list of str
        What was shown to the user.
    """

    spec_path: str
    constants_path: str
    spec: Any
    constants: Any
    marks: List[Any] = field(default_factory=list)
    messages: List[str] = field(default_factory=list)


def write_outputs(spec_path: str, spec_text: str, constants_path: str, constants: Any) -> None:
    """Write the spec and the constants atomically; on failure leave neither behind.

    The spec is written first. If the constants cannot be written, the spec file is put
    back as it was (removed if it is new), so the pair on disk always belongs together.
    """
    os.makedirs(os.path.dirname(os.path.abspath(spec_path)), exist_ok=True)
    previous: Optional[bytes] = None
    if os.path.isfile(spec_path):
        with open(spec_path, "rb") as fh:
            previous = fh.read()
    try:
        write_atomic(spec_path, spec_text)
    except OSError as exc:
        raise InputError(f"cannot write the spec file: {exc.strerror or exc}", spec_path) from exc
    try:
        write_constants(constants, constants_path)
    except BaseException:
        if previous is None:
            try:
                os.unlink(spec_path)
            except FileNotFoundError:
                pass
        else:
            write_atomic(spec_path, previous)
        raise


def _free_id(prefix: str, out_dir: str, scene_stem: str) -> str:
    k = 1
    while os.path.exists(os.path.join(out_dir, f"{scene_stem}.{prefix}{k}.spec.json")):
        k += 1
    return f"{prefix}{k}"


def run_mechanism_command(
    command: str,
    prompter: Prompter,
    scene: Any,
    out_dir: str,
    *,
    scene_name: str,
    mechanism_id: Optional[str] = None,
    name: Optional[str] = None,
) -> Optional[CommandResult]:
    """Run a mechanism command: prompts, spec, constants, then the two files.

    Parameters
    ----------
    command : str
        One of :data:`COMMANDS` (``"RM_SingleBlock"``, ...).
    prompter : Prompter
        Answers the questions.
    scene : cad_maths.scene_3dm.Scene
        The objects the answers refer to (by id).
    out_dir : str
        Folder of ``<scene>.<id>.spec.json`` and ``<scene>.<id>.constants.json``.
    scene_name : str
        The ``.3dm`` file name, for the files' names and provenance.
    mechanism_id : str, optional
        Default: the command's prefix and the first number not used in ``out_dir``.
    name : str, optional
        Description of the mechanism.

    Returns
    -------
    CommandResult or None
        ``None`` when the user cancelled or an answer was invalid; the reason went to
        ``prompter.message`` and no file was written.
    """
    if command not in COMMANDS:
        raise ValueError(f"unknown command {command!r}; expected one of {sorted(COMMANDS)}")
    typology, prefix = COMMANDS[command]
    scene_stem = os.path.splitext(os.path.basename(scene_name))[0] or "scene"
    mech_id = mechanism_id or _free_id(prefix, out_dir, scene_stem)
    stem = f"{scene_stem}.{mech_id}"
    spec_path = os.path.join(out_dir, f"{stem}.spec.json")
    constants_path = os.path.join(out_dir, f"{stem}.constants.json")
    messages: List[str] = []

    def say(text: str) -> None:
        messages.append(text)
        prompter.message(text)

    try:
        mech = FLOWS[typology](prompter, scene, mech_id)
        if name:
            mech["name"] = name
        spec_text = json.dumps({"mechanisms": [mech]}, indent=2) + "\n"
        spec_file = parse_spec(spec_text, os.path.basename(spec_path))
        constants = constants_from_spec(
            spec_file,
            scene,
            scene_name=os.path.basename(scene_name),
            spec_name=os.path.basename(spec_path),
            spec_dir=None,
        )
        marks = check_marks(spec_file, scene, constants)
        write_outputs(spec_path, spec_text, constants_path, constants)
    except Cancelled:
        say(f"{command}: cancelled; nothing was written.")
        return None
    except (RockmechError, ValueError) as exc:  # pydantic's ValidationError is a ValueError
        say(f"{command}: {exc}. Nothing was written.")
        return None
    say(f"{command}: wrote {spec_path} and {constants_path}")
    for m in constants.mechanisms:
        side = m.positive
        eta = f"{m.eta:.4f} ({m.eta_source})" if m.eta is not None else "-"
        say(
            f"  {m.id}: p_eq = {side.p_eq:.4f} rad/s, lambda = {side.lam:.4f}, "
            f"phi_ov = {side.phi_ov:.4f} rad, eta = {eta}"
        )
        if m.negative is not None:
            neg = m.negative
            say(
                f"  {m.id} (negative side): p_eq = {neg.p_eq:.4f} rad/s, "
                f"lambda = {neg.lam:.4f}, phi_ov = {neg.phi_ov:.4f} rad"
            )
        notes = (m.provenance or {}).get("warnings") or []
        for note in notes if isinstance(notes, list) else []:
            say(f"    warning: {note}")
    return CommandResult(spec_path, constants_path, spec_file, constants, marks, messages)
