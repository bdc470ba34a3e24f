"""Readers of the strong-motion formats of the record databases, each detected from its content.

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
number or component name; ``solver_service.core.records`` turns it into a ``GroundMotion``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Optional, Union

from shared_schema.errors import InputError

from . import cosmos, dmg, esm, geonet, knet
from ._text import Channel

__all__ = ["READERS", "Channel", "channel_list", "detect", "select_channel", "truncated"]

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
