"""Boat files of ``sailroute vpp``: a YAML of Laser/ILCA VPP parameters (``docs/vpp.md``)."""

from __future__ import annotations

import re
from pathlib import Path

from sailroute.boat.laser import LaserParams, params_from_mapping
from sailroute.errors import InputError

__all__ = ["load_boat_file", "slug"]


def load_boat_file(path: str | Path) -> tuple[LaserParams, str]:
    """Read a boat YAML (see ``docs/vpp.md``) and return its parameters and a file stem.

    The YAML is read like a course file (YAML 1.2 scalars: ``1e6`` is a number,
    ``no`` is text), and a key given twice is an error rather than silently the
    last value.

    Raises
    ------
    InputError
        Missing file, folder, not UTF-8, an empty file (nothing set: leaving the file
        out says that), YAML syntax error (with line and column), duplicate key, unknown
        key or bad value (with the key and its line), all in one message.
    """
    from sailroute.yamlfile import read_yaml

    p = Path(path)
    ydoc = read_yaml(
        p,
        what="boat file",
        hint="check the path, or leave BOAT.yaml out to use the shipped ILCA 7 parameters",
    )
    doc = ydoc.data
    if doc is None or doc == {}:
        raise InputError(
            f"{p}: the boat file is empty; expected the parameters to change, e.g. "
            "'class: ilca7' and 'crew_mass_kg: 80' (docs/vpp.md), or leave BOAT.yaml out "
            "to use the shipped ILCA 7 parameters"
        )
    if not isinstance(doc, dict):
        raise InputError(
            f"{p}: a boat file is a mapping like 'class: ilca7' and 'crew_mass_kg: 80'; "
            f"got {type(doc).__name__}"
        )
    if ydoc.duplicates:
        d = ydoc.duplicates[0]
        raise InputError(
            f"{p}:{d.line}: {d.path}: the key appears twice (lines "
            f"{d.first_line} and {d.line}); keep one"
        )
    lines = {k: v for k, v in ydoc.lines.items() if "." not in k and "[" not in k}
    return params_from_mapping(doc, where=str(p), lines=lines), slug(p.stem)


def slug(text: str) -> str:
    s = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")
    return s or "boat"
