"""Connection upgrades of a retrofit from a scene: checked against the search spec, applied.

A retrofit spec's ``upgrades`` (``shared_schema.retrofit.ConnectionUpgrade``) name a
junction of the search spec made ``good`` or ``tied``, or a level of it ``tied``. Each is
compared with the designed ties by searching the scene again with the search spec so
changed (``workflows.retrofit_scene``): ``Junction.connection`` (with the ``unit`` of a
junction made good) and ``Level.tied`` are what the search reads.

An upgrade is refused, naming its field, where it names a wall or level the search spec
does not have, a junction the spec neither lists nor covers by its ``default_junction``,
two walls that do not meet in the scene, the same junction or level as another upgrade,
or no upgrade at all (the junction already has that connection or a stronger one, the
level is already tied). Connections rank ``poor < good < tied``.
"""

from __future__ import annotations

from typing import Any, Sequence

from shared_schema.errors import InputError
from shared_schema.retrofit import ConnectionUpgrade
from shared_schema.search import SearchSpec

__all__ = ["STRENGTH", "apply_upgrades", "check_upgrades", "check_upgrades_meet"]

#: How strongly each connection holds two walls together (an upgrade must raise it).
STRENGTH = {"poor": 0, "good": 1, "tied": 2}


def _key(up: ConnectionUpgrade) -> tuple[str, ...]:
    return ("level", up.level or "") if up.walls is None else ("junction", *sorted(up.walls))


def _check_junction(spec: SearchSpec, up: ConnectionUpgrade, k: int) -> str:
    assert up.walls is not None and up.to is not None
    ids = [w.id for w in spec.walls]
    for name in up.walls:
        if name not in ids:
            raise InputError(
                f"no wall {name!r} in the search spec (walls: {', '.join(ids)})",
                f"upgrades[{k}].walls",
            )
    a, b = up.walls
    found = spec.connection_of(a, b)
    if found is None:
        raise InputError(
            f"the search spec has no junction {a}-{b} (not in its junctions, and no "
            "default_junction): list the junction there before upgrading it",
            f"upgrades[{k}].walls",
        )
    now, _, where = found
    if STRENGTH[up.to] <= STRENGTH[now]:
        what = "no change" if up.to == now else f"weaker than its {now}"
        raise InputError(
            f"the junction {a}-{b} is already {now} in the search spec ({where}): {up.to} is "
            f"{what}, not an upgrade",
            f"upgrades[{k}].to",
        )
    return f"junction {a}-{b}: {now} -> {up.to}"


def _check_level(spec: SearchSpec, up: ConnectionUpgrade, k: int) -> str:
    levels = {lv.id: lv for lv in spec.levels}
    if up.level not in levels:
        known = ", ".join(levels) or "none"
        raise InputError(
            f"no level {up.level!r} in the search spec (levels: {known})", f"upgrades[{k}].level"
        )
    if levels[up.level].tied:
        raise InputError(
            f"the level {up.level} is already tied in the search spec: no change, not an upgrade",
            f"upgrades[{k}].tied",
        )
    return f"level {up.level}: tied"


def check_upgrades(spec: SearchSpec, upgrades: Sequence[ConnectionUpgrade]) -> list[str]:
    """Check each upgrade against the search spec; return each in words.

    Returns
    -------
    list of str
        ``"junction F-L: poor -> tied"``, ``"level floor_2: tied"``, in the given order.

    Raises
    ------
    InputError
        Naming the upgrade's field (``upgrades[2].walls``, ``upgrades[0].to``,
        ``upgrades[1].level``, ``upgrades[1].tied``): a wall, junction or level the spec
        does not have, an upgrade that changes nothing or weakens, a junction or level
        upgraded twice.
    """
    words: list[str] = []
    seen: dict[tuple[str, ...], int] = {}
    for k, up in enumerate(upgrades):
        key = _key(up)
        field = f"upgrades[{k}].{'walls' if up.walls is not None else 'level'}"
        if key in seen:
            raise InputError(
                f"the same {key[0]} as upgrades[{seen[key]}]: give each junction or level once",
                field,
            )
        seen[key] = k
        if up.walls is not None:
            words.append(_check_junction(spec, up, k))
        else:
            words.append(_check_level(spec, up, k))
    return words


def check_upgrades_meet(building: Any, upgrades: Sequence[ConnectionUpgrade]) -> None:
    """Refuse a junction upgrade whose two walls do not meet in the searched scene.

    Parameters
    ----------
    building : cad_maths.search.model.Building
        The first search's building (its ``returns``: the walls meeting each façade).

    Raises
    ------
    InputError
        ``upgrades[k].walls``: the walls do not meet (no junction to upgrade).
    """
    for k, up in enumerate(upgrades):
        if up.walls is None:
            continue
        a, b = up.walls
        meet = any(r.wall.id == b for r in building.returns.get(a, [])) or any(
            r.wall.id == a for r in building.returns.get(b, [])
        )
        if not meet:
            raise InputError(
                f"the walls {a} and {b} do not meet in the scene: there is no junction to upgrade",
                f"upgrades[{k}].walls",
            )


def apply_upgrades(spec: SearchSpec, upgrades: Sequence[ConnectionUpgrade]) -> SearchSpec:
    """Return the search spec with the upgrades applied (checked by ``check_upgrades``).

    A junction the spec lists takes the new connection (and the unit of a junction made
    good; a tied one keeps none); a junction its ``default_junction`` covers is added to
    ``junctions``; a level is set ``tied``.
    """
    data = spec.model_dump(exclude_none=True)
    for up in upgrades:
        if up.walls is None:
            for lv in data["levels"]:
                if lv["id"] == up.level:
                    lv["tied"] = True
            continue
        entry: dict[str, Any] = {"walls": list(up.walls), "connection": up.to}
        if up.unit is not None:
            entry["unit"] = up.unit.model_dump()
        pair = sorted(up.walls)
        listed = [j for j in data["junctions"] if sorted(j["walls"]) == pair]
        if listed:
            listed[0].clear()
            listed[0].update(entry)
        else:
            data["junctions"].append(entry)
    return SearchSpec.model_validate(data)
