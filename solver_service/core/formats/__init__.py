"""Readers of every ground-motion record format rockmech reads, one module per format.

The strong-motion databases' formats, each detected from its content (``READERS``):

=========  ==========================================================  =========================
format     files                                                       channels
=========  ==========================================================  =========================
``esm``    ESM / ITACA ASCII, DYNA 1.2 header (``*.ASC``)              one
``knet``   NIED K-NET and KiK-net ASCII (``*.NS``, ``*.EW2``, ...)     one (mean removed)
``cosmos`` COSMOS V2 corrected acceleration (``*.V2c``)                usually one
``dmg``    CSMIP / DMG V2 (``*.V2``)                                   several
``geonet`` GeoNet V2A (New Zealand)                                    three
=========  ==========================================================  =========================

Each module has ``sniff(head) -> bool`` (the first lines of a file) and
``read(text, name) -> list[Channel]`` (every acceleration channel, in the units its header
states, checked against the header's sample count and peak). ``select_channel`` picks one by
number or component name.

The other formats: ``at2`` (PEER NGA, ``sniff`` and ``read(text, name)`` like the above, one
channel), and the plain-text column files, which state no units or time step of their own,
so their ``read`` takes them: ``two_column.read(text, name, units)``,
``one_column.read(text, name, dt, units)`` and ``csv.read(text, name, units, time_column,
accel_column, dt)``, each returning one ``Channel``. ``format_of`` tells a file's format from
its extension and content, and ``dt_source`` where a record's time step came from.
``solver_service.core.records`` reads the file and turns a ``Channel`` into an SI
``GroundMotion``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Optional, Union

from shared_schema.errors import InputError
from shared_schema.rules import RECORD_FORMATS

from . import at2, cosmos, csv, dmg, esm, geonet, knet, one_column, two_column
from ._columns import DT_RTOL, check_samples, check_step, data_lines
from ._text import Channel

__all__ = [
    "DT_RTOL",
    "DT_SOURCES",
    "EXTENSIONS",
    "READERS",
    "Channel",
    "at2",
    "channel_list",
    "check_samples",
    "check_step",
    "csv",
    "detect",
    "dt_source",
    "format_of",
    "one_column",
    "select_channel",
    "truncated",
    "two_column",
]

#: Format name -> (sniff, read), in the order detection tries them.
READERS: dict[str, tuple[Callable[[str], bool], Callable[[str, str], list[Channel]]]] = {
    "esm": (esm.sniff, esm.read),
    "knet": (knet.sniff, knet.read),
    "cosmos": (cosmos.sniff, cosmos.read),
    "dmg": (dmg.sniff, dmg.read),
    "geonet": (geonet.sniff, geonet.read),
}
#: Characters of a file's start that detection looks at.
HEAD_CHARS = 4096
#: File extensions (lower case) that fix the format.
EXTENSIONS = {".at2": "at2", ".csv": "csv"}
#: Where each format's time step comes from, for the plausibility warning (``samples``: a
#: record built from samples in memory).
DT_SOURCES: dict[str, str] = {
    "at2": at2.DT_SOURCE,
    "two_column": two_column.DT_SOURCE,
    "one_column": one_column.DT_SOURCE,
    **{
        fmt: module.DT_SOURCE
        for fmt, module in {
            "esm": esm,
            "knet": knet,
            "cosmos": cosmos,
            "dmg": dmg,
            "geonet": geonet,
        }.items()
    },
    "samples": "dt",
}


def detect(text: str) -> Optional[str]:
    """Return the format whose header ``text`` starts with, or None."""
    head = text[:HEAD_CHARS].replace("\r\n", "\n")
    for fmt, (sniff, _) in READERS.items():
        if sniff(head):
            return fmt
    return None


def truncated(text: str, name: str) -> Optional[str]:
    """Return why a file that starts like a strong-motion header but is cut short is refused.

    For the files ``detect`` does not recognise: an ESM / ITACA header cut before the keys
    that identify it (``esm.truncated_header``); None for any other file.
    """
    return esm.truncated_header(text[:HEAD_CHARS].replace("\r\n", "\n"), name)


def channel_list(channels: list[Channel]) -> str:
    """``1: 90 DEG, 2: UP, 3: 0 DEG``: how a message lists the channels of a file."""
    return ", ".join(f"{c.metadata['channel']}: {c.metadata['component']}" for c in channels)


def select_channel(
    channels: list[Channel],
    name: str,
    channel: Union[int, str, None] = None,
    component: Optional[str] = None,
) -> Channel:
    """Pick one channel by its number in the file or its component name (case-insensitive).

    Parameters
    ----------
    channels : list of Channel
        Every acceleration channel of the file.
    name : str
        File name for messages.
    channel : int or str, optional
        The channel's number as the file gives it (``CHAN 2``; 1-based order otherwise).
    component : str, optional
        The component as its header names it (``S16W``, ``Up``, ``90 DEG``, ``E-W``, ``HNE``).

    Raises
    ------
    InputError
        Several channels and none chosen (field ``channel``, listing them), or no channel
        matching (``channel`` or ``component``).
    """
    chosen = channels
    if channel is not None:
        text = str(channel).strip()
        chosen = [c for c in chosen if str(c.metadata["channel"]) == text]
        if not chosen:
            raise InputError(
                f"{name} has no channel {text!r}; channels: {channel_list(channels)}", "channel"
            )
    if component is not None:
        key = "".join(component.split()).casefold()
        chosen = [c for c in chosen if "".join(c.metadata["component"].split()).casefold() == key]
        if not chosen:
            raise InputError(
                f"{name} has no component {component!r}; channels: {channel_list(channels)}",
                "component",
            )
    if len(chosen) > 1:
        raise InputError(
            f"{name} holds {len(chosen)} acceleration channels; choose one with channel "
            f"(number) or component (name): {channel_list(chosen)}",
            "channel",
        )
    return chosen[0]


def format_of(text: str, name: str, suffix: str = "") -> str:
    """Return the format of a record file from its extension, else its content.

    Parameters
    ----------
    text : str
        The file's text (not looked at for an extension in ``EXTENSIONS``).
    name : str
        File name, for messages.
    suffix : str
        The file's extension (``.AT2``, ``.csv``; any case).

    Returns
    -------
    str
        From the extension (``.AT2``, ``.csv``), else a PEER title (``at2``), a strong-motion
        header (``detect``), else the count of numbers on the first data line (2:
        ``two_column``, 1: ``one_column``).

    Raises
    ------
    InputError
        A strong-motion header cut short, an empty file (field ``record``), or a file whose
        format cannot be told (``format``).
    """
    fmt = EXTENSIONS.get(suffix.lower())
    if fmt is not None:
        return fmt
    if at2.sniff(text):
        return "at2"
    strong = detect(text)
    if strong is not None:
        return strong
    cut = truncated(text, name)
    if cut is not None:
        raise InputError(cut, "record")
    lines = data_lines(text)
    if not lines:
        raise InputError(f"{name} is empty: no data lines to read", "record")
    first = lines[0][2].replace(",", " ").split()
    try:
        [float(x) for x in first]
    except ValueError:
        first = []
    if len(first) == 2:
        return "two_column"
    if len(first) == 1:
        return "one_column"
    raise InputError(
        f"cannot tell the format of {name} (line {lines[0][0]}: {lines[0][1].strip()!r}); "
        f"give format, one of {list(RECORD_FORMATS)}",
        "format",
    )


def dt_source(meta: dict[str, Any]) -> str:
    """Where a record's time step was read from (a header field, a column, or given)."""
    fmt = meta.get("format")
    if fmt == "csv":
        timed = meta.get("time_column") is not None
        return DT_SOURCES["two_column"] if timed else DT_SOURCES["one_column"]
    return DT_SOURCES.get(str(fmt), "the time step given")
