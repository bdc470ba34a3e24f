"""``rockmech retrofit --scene SCENE --search-spec SPEC``: the retrofit of a searched scene.

``--scene`` may be the run folder of ``rockmech search --out``: its ``search.3dm`` is searched
and must give the folder's ``constants.json`` again.

The search runs, the retrofit designs the ties of its failing mechanisms, the ties go into the
scene as tie-bars and the search runs again (``workflows.retrofit_scene``). The workflow (the
search, scipy, the geometry) is imported when the command runs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Optional, Sequence

from shared_schema.errors import InputError
from shared_schema.rules import check_file

from .output import status

__all__ = ["retrofit_document", "scene_retrofit", "search_after_lines", "upgrade_lines"]


def retrofit_document(
    constants: Optional[Path],
    scene: Optional[Path],
    search_spec: Optional[Path],
    site: Any,
    rspec: Any,
    motions: Sequence[Any],
    limits: Any,
) -> Any:
    """Return the ``RetrofitDoc`` of a constants file, or of a scene searched (``--scene``).

    The work limit (``limits.check_retrofit_work``) is checked before the retrofit runs,
    unless ``--no-limits``.
    """
    # The constants reader is loaded when the command runs.
    from ..workflows import inputs

    # The up-front work estimate.
    from ..workflows.limits import NO_LIMITS, TIME_LIMIT, check_retrofit_work, retrofit_reruns

    # The retrofit (the code checks, scipy) is loaded when the command runs.
    from ..workflows.retrofit import retrofit_doc

    how = f"give {TIME_LIMIT} with more seconds, or {NO_LIMITS}"

    from_scene = scene is not None or search_spec is not None

    def check_work(cf: Any, rs: Any) -> None:
        # From a scene the search runs again (the ties, each upgrade): those checks count.
        reruns = retrofit_reruns(rs) if from_scene else 0
        if not limits.no_limits:
            check_retrofit_work(cf, site, rs, limits.time_limit, how, motions, reruns)

    if from_scene:
        return scene_retrofit(
            constants, scene, search_spec, site, rspec, motions, limits, check_work
        )
    if constants is None:
        raise InputError(
            "give a constants file, or a scene with --scene and --search-spec", "constants"
        )
    cf = inputs.read_constants(constants)
    check_work(cf, rspec)
    with status("retrofit: code checks and tie forces"):
        return retrofit_doc(cf, site, rspec, motions)


def scene_retrofit(
    constants: Optional[Path],
    scene: Optional[Path],
    search_spec: Optional[Path],
    site: Any,
    rspec: Any,
    motions: Sequence[Any],
    limits: Any,
    check_work: Callable[[Any, Any], None],
) -> Any:
    """Run the retrofit of a scene for the command line; return the ``RetrofitDoc``.

    Raises
    ------
    InputError
        A constants file with ``--scene`` (one source of mechanisms), ``--scene`` without
        ``--search-spec`` or the other way round.
    """
    if constants is not None:
        raise InputError(
            "give either a constants file or --scene with --search-spec, not both: the "
            "scene's mechanisms are the search's",
            "constants",
        )
    if scene is None or search_spec is None:
        missing = "--search-spec" if scene is not None else "--scene"
        raise InputError(
            f"a retrofit from a scene needs --scene and --search-spec; {missing} is missing",
            missing.lstrip("-").replace("-", "_"),
        )
    # The scene reader (rhino3dm, trimesh) is loaded when the command runs.
    from cad_maths.scenes import read_scene

    # The searches and the retrofit (scipy, the geometry) are loaded when the command runs.
    from ..workflows.retrofit_scene import retrofit_search

    # The search spec's reader and the search's work limits, with the search.
    from ..workflows.search import MAX_EVALUATIONS, MAX_LP_BLOCKS, read_search_spec

    expected = None
    if scene.is_dir():
        # A search's run folder: its own scene, and the constants the search must rebuild.
        from ..workflows.inputs import read_constants

        folder, scene = scene, scene / "search.3dm"
        if not scene.is_file():
            raise InputError(
                f"{folder.name} is a folder without search.3dm: give a scene, or the run "
                "folder of `rockmech search --out`",
                "scene",
            )
        if (folder / "constants.json").is_file():
            expected = read_constants(folder / "constants.json")
    spec = read_search_spec(search_spec)
    scene_obj = read_scene(check_file(scene, "scene"))
    with status("retrofit: search, tie forces, search again with the ties"):
        run = retrofit_search(
            scene_obj,
            spec,
            site,
            rspec,
            motions,
            scene_name=scene.name,
            spec_name=search_spec.name,
            max_evaluations=None if limits.no_limits else MAX_EVALUATIONS,
            max_lp_blocks=None if limits.no_limits else MAX_LP_BLOCKS,
            check_work=check_work,
            expected=expected,
        )
    return run.doc


def _g(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.3f}"


def search_after_lines(sa: Any) -> list[str]:
    """Return the lines the command prints about the search rerun with the ties in."""
    out = []
    for t in sa.ties:
        if t.status == "placed":
            out.append(
                f"  {t.mechanism}: tie-bar '{t.object}' on {t.wall} at z = {t.at_m[2]:.4g} m "
                f"({t.height_m:.4g} m above the hinge), {t.force_N / 1e3:.4g} kN"
            )
        else:
            out.append(f"  {t.mechanism}: not put in the scene: {t.note}")
    if sa.after is None:
        out.extend(f"  {n}" for n in sa.notes)
        return out + upgrade_lines(sa)
    where = "another mechanism" if sa.moved else "the same mechanism"
    if sa.moved and sa.after_facade != sa.before_facade:
        where = f"another wall ({sa.before_facade} -> {sa.after_facade})"
    out.append(
        f"search again with the ties (its own mechanisms): {sa.after} governs, margin "
        f"{_g(sa.after_margin)} ({sa.after_criterion}), lambda0 {sa.after_lam0:.4g}: "
        f"{sa.after_name}"
    )
    out.append(
        f"  before: {sa.before} at {_g(sa.before_margin)} ({sa.before_criterion}); the "
        f"collapse moves to {where}"
        if sa.moved
        else f"  before: {sa.before} at {_g(sa.before_margin)} ({sa.before_criterion}); "
        f"{where} governs"
    )
    return out + upgrade_lines(sa)


def upgrade_lines(sa: Any) -> list[str]:
    """Return the lines the command prints about the searches with connection upgrades."""
    out = []
    for u in [*sa.upgrades, *([sa.together] if sa.together is not None else [])]:
        what = " + ".join(u.upgrades) + (" + the designed ties" if u.with_ties else "")
        if u.after is None:
            out.append(f"search again with {what}: {'; '.join(u.notes) or 'no margin'}")
            continue
        out.append(
            f"search again with {what}: {u.after} governs, margin {_g(u.after_margin)} "
            f"({u.after_criterion}), lambda0 {u.after_lam0:.4g}"
            + ("; the collapse moves" if u.moved else "")
            + f": {u.after_name}"
        )
    return out
