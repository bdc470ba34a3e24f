"""One entry point for every scene file: ``.3dm`` models and scan meshes.

:func:`read_scene` picks the reader from the file's extension: Rhino ``.3dm``
(:class:`~cad_maths.scene_3dm.Scene`, units from the file) or a scan mesh ``.ply``,
``.obj``, ``.stl``, ``.off`` (:class:`~cad_maths.scene_mesh.MeshScene`, units given).
The CLI, the service and the demo call it; each reader stays importable on its own.

Python 3.9-clean.
"""

import os
from typing import Optional, Union

from cad_maths.scene_3dm import Scene
from cad_maths.scene_base import BaseScene
from cad_maths.scene_mesh import SCAN_FORMATS, MeshScene, unit_ratio
from shared_schema.errors import InputError
from shared_schema.paths import readable_file

__all__ = ["SCENE_FORMATS", "read_scene"]

#: Extensions :func:`read_scene` reads (lower case, without the dot).
SCENE_FORMATS = ("3dm", *SCAN_FORMATS)
#: Model-unit names of a .3dm file saved without units (read as metres by default).
UNITLESS_3DM = ("none", "unset")
#: What :func:`read_scene` reads, in words, for the message on anything else.
SCENE_SOURCES = "a path (str or os.PathLike, e.g. pathlib.Path) or the file's bytes"


def read_scene(
    source: Union[str, "os.PathLike[str]", bytes],
    *,
    name: Optional[str] = None,
    units: Optional[str] = None,
) -> BaseScene:
    """Read a scene from a file or from bytes.

    Parameters
    ----------
    source : str, path-like or bytes
        The file, or its content (an upload).
    name : str, optional
        File name used for the format (its extension) and in messages; required with
        bytes, defaults to ``source``'s path otherwise.
    units : str, optional
        Length unit of a scan mesh: mm, cm, m, in or ft (required for .ply, .obj, .stl and
        .off, which carry none). A ``.3dm`` file has its own units: ``units`` may repeat
        them but not contradict them, except in a file saved without units (read as metres
        unless ``units`` is given).

    Returns
    -------
    BaseScene
        A :class:`~cad_maths.scene_3dm.Scene` or a
        :class:`~cad_maths.scene_mesh.MeshScene`, in metres.

    Raises
    ------
    InputError
        Unknown format; a missing file, a folder, an unreadable file or a ``source`` that is
        neither a path (``str``, ``os.PathLike``) nor bytes (field ``"scene"``, naming the
        path); or missing, unknown or contradicting ``units`` (field ``"units"``).

    Examples
    --------
    >>> read_scene("examples/scenes/rect_wall.3dm").units
    'meters'
    >>> read_scene(b"...", name="wall.ply")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    shared_schema.errors.InputError: units: wall.ply: a .ply file carries no length unit; give...
    """
    if isinstance(source, (bytes, bytearray, memoryview)):
        if not name:
            raise InputError("a scene given as bytes needs its file name", "scene")
        label = name
    else:
        source = readable_file(source, "scene", SCENE_SOURCES)
        label = name or str(source)
    ext = os.path.splitext(label)[1].lower().lstrip(".")
    if ext not in SCENE_FORMATS:
        raise InputError(
            f"{os.path.basename(label)}: unknown scene format {('.' + ext) if ext else '(none)'}; "
            "rockmech reads " + ", ".join("." + e for e in SCENE_FORMATS),
            "scene",
        )
    if isinstance(source, (bytes, bytearray, memoryview)):
        size = len(source)
    else:
        size = os.path.getsize(source) if os.path.isfile(source) else 1
    if size == 0:
        raise InputError(
            f"{os.path.basename(label)} is empty (0 bytes): expected a scene (a Rhino .3dm model, "
            "or a .ply, .obj, .stl or .off scan mesh); check that it was saved or copied "
            "completely",
            "scene",
        )
    if ext != "3dm":
        if isinstance(source, (bytes, bytearray, memoryview)):
            return MeshScene.from_bytes(bytes(source), label, units=units)
        return MeshScene.from_file(source, units=units)
    if isinstance(source, (bytes, bytearray, memoryview)):
        scene = Scene.from_bytes(bytes(source), label)
    else:
        scene = Scene.from_3dm(source)
    if units is not None:
        long, (num, den) = unit_ratio(units, label)
        if scene.units in UNITLESS_3DM:
            # a model saved without units: the caller says what they are
            scene.units, scene._ratio = long, (num, den)
            scene.unit_scale, scene.tolerance = num / den, scene.tolerance * num / den
        elif long != scene.units:
            raise InputError(
                f"{os.path.basename(label)} is in {scene.units} (its model units), not "
                f"{long}; drop units for a .3dm file",
                "units",
            )
    return scene
