"""The ``routing:`` section of a course file -> :class:`RoutingSettings`.

The section takes the common fields (``router``, ``tack_penalty_s``, ``zone_m``, ...),
each router's fields under its flat name (``dt_s``, ``dp_cols``, ``spline_slopes``; see
:data:`~sailroute.routing.settings.FLAT_NAMES`) and a section per router, named as the
router, with the fields of its settings class (``griddp: {cols: 64}``; the class is
``RouterEntry.settings_type`` of :data:`~sailroute.routing.api.ROUTERS`).  Each value is
type-checked by its field's annotation; a key given both flat and in a router's section
is refused; the routers' own rules then run on the result, each problem located at the
key the file used and naming it as the file does.
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from sailroute.checks import Checker
from sailroute.routing.api import ROUTERS
from sailroute.routing.settings import (
    COMMON_FIELDS,
    FLAT_NAMES,
    MIN_DT_S,
    MIN_HEADING_STEP_DEG,
    RoutingSettings,
    flat_name,
    settings_problems,
    with_paths,
)
from sailroute.routing.types import SIDE_NAMES, RouterName


@dataclass(frozen=True)
class _Key:
    """One key of the section: where it is and which settings it gives."""

    checker: Checker
    """Checker of the mapping that holds it (``routing`` or ``routing.griddp``)."""
    raw: Mapping[str, Any]
    key: str
    shown: str
    """The key below ``routing`` as the file writes it: ``"dp_cols"``, ``"griddp.cols"``."""
    paths: tuple[str, ...]
    """The fields it sets (``"griddp.cols"``; ``dp_rows`` sets two)."""


def _dt(r: Checker, d: Mapping[str, Any], key: str) -> Any:
    return r.number(
        d,
        key,
        lo=MIN_DT_S,
        what=(
            f"a time step >= {MIN_DT_S:g} s (default 10; finer steps hardly change the "
            "route and make it slow)"
        ),
    )


def _heading_step(r: Checker, d: Mapping[str, Any], key: str) -> Any:
    return r.number(
        d,
        key,
        lo=MIN_HEADING_STEP_DEG,
        hi=45.0,
        what=(
            f"a number in [{MIN_HEADING_STEP_DEG:g}, 45] (default 2; finer steps only slow "
            "the router)"
        ),
    )


_SPECIAL: dict[str, Callable[[Checker, Mapping[str, Any], str], Any]] = {
    "router": lambda r, d, k: r.choice(d, k, typing.get_args(RouterName)),
    "isochrone.dt_s": _dt,
    "isochrone.heading_step_deg": _heading_step,
    "tack_penalty_s": lambda r, d, k: r.number(d, k, lo=0.0),
    "gybe_penalty_s": lambda r, d, k: r.number(d, k, lo=0.0),
    "initial_side": lambda r, d, k: r.choice(d, k, (*SIDE_NAMES, None)),
}
"""Fields checked with their own range and wording (the others by their annotation)."""


def _annotation(path: str) -> str:
    """The type annotation of a field path, as text (``"int"``, ``"float | None"``)."""
    group, _, attr = path.partition(".")
    cls: type = ROUTERS[group].settings_type if attr else RoutingSettings
    name = attr or group
    return str(next(f.type for f in dataclasses.fields(cls) if f.name == name))


def _generic(r: Checker, raw: Mapping[str, Any], key: str, type_text: str) -> Any:
    """Type-check a settings field by its annotation (``float``, ``int | None``, ...)."""
    optional = "None" in type_text
    if optional and raw[key] is None:
        return None
    if "bool" in type_text:
        return r.boolean(raw, key, False)
    if "int" in type_text:
        return r.integer(raw, key, None, lo=0)
    if "float" in type_text:
        return r.number(raw, key, what="a number" + (" or null" if optional else ""))
    if "str" in type_text or "Literal" in type_text:
        return r.string(raw, key)
    return raw[key]


def _section_keys(r: Checker, raw: Mapping[str, Any], group: str) -> list[_Key]:
    """The keys of a router's section ``routing.<group>`` (unknown ones recorded)."""
    value = raw[group]
    if value is None:  # `griddp:` with nothing below: the defaults
        return []
    sub = r.child(group)
    if not sub.is_mapping(value, f"a mapping of {group} router settings"):
        return []
    fields = [f.name for f in dataclasses.fields(ROUTERS[group].settings_type)]
    sub.keys(value, fields, of=f"the {group} router")
    return [_Key(sub, value, k, f"{group}.{k}", (f"{group}.{k}",)) for k in value if k in fields]


def _keys(r: Checker, raw: Mapping[str, Any]) -> list[_Key]:
    """Every known key of the section, flat and in the routers' sections, each field once
    (a field given twice is recorded at its second key)."""
    seen: dict[str, str] = {}
    out: list[_Key] = []
    for key in raw:
        if key in ROUTERS:
            found = _section_keys(r, raw, key)
        elif key in COMMON_FIELDS or key in FLAT_NAMES:
            found = [_Key(r, raw, key, key, FLAT_NAMES.get(key, (key,)))]
        else:
            continue  # unknown: recorded by Checker.keys
        for k in found:
            twice = [p for p in k.paths if p in seen]
            if twice:
                first = seen[twice[0]]
                line = r.p.line_of(f"routing.{first}")
                k.checker.add(
                    k.key,
                    f"given twice (also as routing.{first}"
                    + (f", line {line}" if line is not None else "")
                    + "); keep one: a flat key and a router's section set the same setting",
                )
                continue
            seen.update(dict.fromkeys(k.paths, k.shown))
            out.append(k)
    return out


def load_routing(c: Checker, raw: Any) -> RoutingSettings:
    """The course's routing settings from its ``routing:`` section (``raw``; None: absent).

    Problems go to ``c`` with the file's line: an unknown key (with a did-you-mean), a
    key given twice (flat and in a router's section), a value of the wrong type or out
    of range, and the routers' own rules
    (:func:`~sailroute.routing.settings.settings_problems`), at load time rather than
    mid-plan.  After a problem the field keeps its default.
    """
    if raw is None:
        return RoutingSettings()
    r = c.at("routing")
    if not r.is_mapping(raw, "a mapping of routing settings"):
        return RoutingSettings()
    r.keys(raw, [*COMMON_FIELDS, *FLAT_NAMES, *ROUTERS])
    keys = _keys(r, raw)
    values: dict[str, Any] = {}
    for k in keys:
        check = _SPECIAL.get(k.paths[0])
        v = (
            check(k.checker, k.raw, k.key)
            if check is not None
            else _generic(k.checker, k.raw, k.key, _annotation(k.paths[0]))
        )
        if v is not None or k.raw[k.key] is None:
            values.update(dict.fromkeys(k.paths, v))
    try:
        settings = with_paths(RoutingSettings(), values)
    except (TypeError, ValueError) as exc:  # a future field with its own checks
        r.add(None, str(exc))
        return RoutingSettings()
    shown = {p: k.shown for k in keys for p in k.paths}
    nested = {g for g in ROUTERS if g in raw}

    def name(path: str) -> str:
        """A field as the file names it: its key, else in the form the file uses."""
        if path in shown:
            return shown[path]
        return path if path.partition(".")[0] in nested else flat_name(path)

    for problem in settings_problems(settings, name):
        word = problem.split(" ", 1)[0]
        c.p.add(f"routing.{word}" if word in shown.values() else "routing", problem)
    return settings
