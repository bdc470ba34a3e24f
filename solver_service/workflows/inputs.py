"""Reading what users give: records (format detected), constants files, scenes with specs."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

from rhino_plugin.mechanisms.build import (
    MechanismFailure,
    constants_and_failures,
    constants_from_spec,
    failures_error,
)
from rhino_plugin.scene_3dm import Scene
from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError
from shared_schema.io import load_constants
from shared_schema.spec import parse_spec

from ..core.records import GroundMotion, detect_format

__all__ = ["constants_from_files", "constants_keep_going", "read_constants", "read_record"]


def _require_file(path: Path, label: str) -> None:
    if path.is_dir():
        raise InputError(f"is a folder, not a file: {path}", label)
    if not path.is_file():
        raise InputError(f"file not found: {path}", label)


def read_record(
    path: Path,
    fmt: Optional[str] = None,
    units: Optional[str] = None,
    dt: Optional[float] = None,
) -> GroundMotion:
    """Read a record as ``rockmech`` does: format detected, a two-column file in g by default.

    Parameters
    ----------
    path : Path
        The record file.
    fmt, units, dt
        As ``GroundMotion.from_file``; ``units`` defaults to g for a two-column file (the
        t [s], a [g] convention of the bundled record).
    """
    fmt = fmt or detect_format(path)
    if units is None and fmt == "two_column":
        units = "g"
    return GroundMotion.from_file(path, format=fmt, units=units, dt=dt)


def read_constants(path: Path) -> ConstantsFile:
    """Read and validate a kinematic-constants file; errors name ``constants``."""
    _require_file(path, "constants")
    return load_constants(path)


def constants_from_files(scene: Path, spec: Path) -> ConstantsFile:
    """Kinematic constants of every mechanism of a spec file from the solids of a scene file.

    Parameters
    ----------
    scene : Path
        Rhino ``.3dm`` file (read with rhino3dm).
    spec : Path
        Mechanism spec (JSON); relative paths inside it are taken from its folder.

    Raises
    ------
    RockmechError
        If any mechanism fails; the message lists every failed mechanism.
    """
    for label, path in (("scene", scene), ("spec", spec)):
        _require_file(path, label)
    spec_file = parse_spec(spec.read_bytes(), spec.name)
    return constants_from_spec(
        spec_file,
        Scene.from_3dm(scene),
        scene_name=scene.name,
        spec_name=spec.name,
        spec_dir=spec.parent,
    )


def constants_keep_going(scene: Path, spec: Path) -> tuple[ConstantsFile, list[MechanismFailure]]:
    """Like ``constants_from_files``, but keep the mechanisms that succeed.

    Returns
    -------
    constants : ConstantsFile
        The mechanisms that succeeded, in spec order.
    failures : list of MechanismFailure
        The mechanisms that failed, each with its error.

    Raises
    ------
    RockmechError
        If the files cannot be read, or if every mechanism fails (nothing to write).
    """
    for label, path in (("scene", scene), ("spec", spec)):
        _require_file(path, label)
    spec_file = parse_spec(spec.read_bytes(), spec.name)
    cf, failures = constants_and_failures(
        spec_file,
        Scene.from_3dm(scene),
        scene_name=scene.name,
        spec_name=spec.name,
        spec_dir=spec.parent,
    )
    if cf is None:
        raise failures_error(failures, len(spec_file.mechanisms))
    return cf, failures
