"""A learned polar's file: sailroute's JSON polar with a ``learned`` block.

The file is an ordinary sailroute JSON polar (:func:`sailroute.boat.io.write_polar_json`):
its ``twa_deg``/``tws``/``speed`` are the default level's table, so any reader of the
format reads it.  The ``learned`` block adds what :class:`~sailroute.boat.learn.LearnedPolar`
holds, in the file's ``speed_unit``::

    learned:
      default_level: median
      levels:
        median: {percentile: 50, speed: [[...]], sd_log: [[...]], p10: [[...]],
                 p90: [[...]], modes: [[[...]]], resid_sd_log: [[...]],
                 vmg_up: [...], vmg_down: [...],
                 race_pace: {upwind: 0.91, reach: 0.95, downwind: 0.88} or null}
        top: {...}
      cells: {blocks: [[...]], boats: [[...]], seconds: [[...]], status: [[...]]}
      refused: ["TWA 30 deg, TWS 4.12 m/s: 1 boat(s), need 2", ...]
      verdict: [...]
      provenance: {boats: [...], races: [...], wind_sources: [...], ...}

``sd_log``, ``modes`` and ``resid_sd_log`` are relative (of ``log speed``) and carry no
unit.  :func:`read_learned` reads it back; a course names a level with
``boat: {polar: FILE.json, level: top}`` (:mod:`sailroute.boat.build`).
"""

from __future__ import annotations

import json
from pathlib import Path
from types import MappingProxyType
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.io import read_polar, write_polar_json
from sailroute.boat.learn import BAND_NAMES, DEFAULT_LEVEL, LearnedPolar, LevelTable
from sailroute.errors import InputError
from sailroute.units import speed_factor

LEARNED_KEY: Final = "learned"
"""Top-level key of the learned block."""
_STATUSES: Final = ("learned", "refused", "empty")


def _table(a: NDArray, f: float = 1.0, decimals: int = 5) -> list[Any]:
    return np.round(np.asarray(a, float) / f, decimals).tolist()


def _num_or_none(v: NDArray, f: float) -> list[float | None]:
    return [None if not np.isfinite(x) else round(float(x) / f, 5) for x in v]


def learned_to_dict(learned: LearnedPolar, unit: str) -> dict[str, Any]:
    """The ``learned`` block of a learned polar's file (speeds in ``unit``)."""
    f = speed_factor(unit)
    levels = {}
    for name, t in learned.levels.items():
        levels[name] = {
            "percentile": t.percentile,
            "speed": _table(t.speed_ms, f),
            "sd_log": _table(t.sd_log, decimals=5),
            "p10": _table(t.p10_ms, f),
            "p90": _table(t.p90_ms, f),
            "modes": _table(t.modes, decimals=5),
            "resid_sd_log": _table(t.resid_sd_log, decimals=5),
            "vmg_up": _num_or_none(t.vmg_up_ms, f),
            "vmg_down": _num_or_none(t.vmg_down_ms, f),
            "race_pace": None
            if t.race_pace is None
            else {b: round(float(v), 5) for b, v in zip(BAND_NAMES, t.race_pace, strict=True)},
            "pace_sd_log": None if t.pace_sd_log is None else round(float(t.pace_sd_log), 5),
        }
    return {
        "default_level": DEFAULT_LEVEL if DEFAULT_LEVEL in learned.levels else next(iter(levels)),
        "levels": levels,
        "cells": {
            "blocks": learned.blocks.tolist(),
            "boats": learned.boats.tolist(),
            "seconds": _table(learned.seconds, decimals=1),
            "status": learned.status.tolist(),
        },
        "refused": list(learned.reasons),
        "verdict": list(learned.verdict),
        "provenance": _jsonable(dict(learned.provenance)),
    }


def _jsonable(v: Any) -> Any:
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, np.ndarray):
        return _jsonable(v.tolist())
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    return v


def write_learned(
    learned: LearnedPolar, path: str | Path, unit: str = "kn", extra: dict[str, Any] | None = None
) -> Path:
    """Write the learned polar's JSON (the default level's table plus ``learned``, plus
    the top-level keys of ``extra``)."""
    return write_polar_json(
        learned.polar(None).with_name(learned.name),
        path,
        unit=unit,
        decimals=5,
        extra={**(extra or {}), LEARNED_KEY: learned_to_dict(learned, unit)},
    )


def is_learned(path: str | Path) -> bool:
    """True when ``path`` is a JSON polar with a ``learned`` block (cheap check)."""
    p = Path(path)
    if p.suffix.lower() != ".json":
        return False
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return False
    return isinstance(doc, dict) and isinstance(doc.get(LEARNED_KEY), dict)


def read_learned(path: str | Path, interpolation: str = "pchip") -> LearnedPolar:
    """Read a learned polar's file.

    The default table is read and checked by :func:`sailroute.boat.io.read_polar` (its
    grid and units); each level's arrays must have the table's shape.

    Raises
    ------
    InputError
        Not a learned polar, or a level, array or key that does not fit (the message
        names the key).
    """
    p = Path(path)
    base = read_polar(p, format="json", interpolation=interpolation)
    doc = json.loads(p.read_text(encoding="utf-8"))
    blk = doc.get(LEARNED_KEY) if isinstance(doc, dict) else None
    if not isinstance(blk, dict):
        raise InputError(
            f"{p}: not a learned polar (no '{LEARNED_KEY}' block); levels come from "
            "`sailroute polar fit` files"
        )
    f = speed_factor(str(doc["speed_unit"]))
    shape = base.speed_ms.shape
    m, n = shape

    def arr(obj: Any, key: str, where: str, scale: float = 1.0, dims: int = 2) -> NDArray:
        try:
            a = np.asarray(obj[key], dtype=float) * scale
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{p}: {where}.{key}: missing or not numbers ({exc})") from None
        want = {1: (n,), 2: shape}.get(dims)
        if dims == 3 and a.size == 0:  # learned without a bootstrap: no modes
            a = a.reshape(0, m, n)
        if (want is not None and a.shape != want) or (dims == 3 and a.shape[1:] != shape):
            raise InputError(
                f"{p}: {where}.{key} has shape {a.shape}; expected "
                f"{want if want is not None else ('k', m, n)} (the table's TWA rows x TWS columns)"
            )
        return a

    levels_doc = blk.get("levels")
    if not isinstance(levels_doc, dict) or not levels_doc:
        raise InputError(f"{p}: {LEARNED_KEY}.levels: expected a mapping of level names")
    levels = {}
    for name, lv in levels_doc.items():
        where = f"{LEARNED_KEY}.levels.{name}"
        if not isinstance(lv, dict):
            raise InputError(f"{p}: {where}: expected a mapping")
        pace = lv.get("race_pace")
        pace_t: tuple[float, float, float] | None = None
        if pace is not None:
            try:
                up, reach, down = (float(pace[b]) for b in BAND_NAMES)
                pace_t = (up, reach, down)
            except (KeyError, TypeError, ValueError) as exc:
                raise InputError(
                    f"{p}: {where}.race_pace: expected {{upwind, reach, downwind}} factors ({exc})"
                ) from None
            if not all(0.0 < v < 3.0 for v in (up, reach, down)):
                raise InputError(f"{p}: {where}.race_pace: factors must lie in (0, 3)")
        sd_pace = lv.get("pace_sd_log")
        if sd_pace is not None and (
            not isinstance(sd_pace, int | float) or not 0.0 <= float(sd_pace) < 1.0
        ):
            raise InputError(
                f"{p}: {where}.pace_sd_log: expected a number in [0, 1) or null; got {sd_pace!r}"
            )
        speed = arr(lv, "speed", where, f)
        if not np.all(np.isfinite(speed)) or np.any(speed < 0):
            raise InputError(f"{p}: {where}.speed: boat speeds must be finite and >= 0")
        levels[str(name)] = LevelTable(
            name=str(name),
            percentile=float(lv.get("percentile", np.nan)),
            speed_ms=speed,
            sd_log=arr(lv, "sd_log", where),
            p10_ms=arr(lv, "p10", where, f),
            p90_ms=arr(lv, "p90", where, f),
            modes=arr(lv, "modes", where, dims=3),
            resid_sd_log=arr(lv, "resid_sd_log", where),
            vmg_up_ms=np.asarray(
                [np.nan if v is None else float(v) * f for v in lv.get("vmg_up", [None] * n)]
            ),
            vmg_down_ms=np.asarray(
                [np.nan if v is None else float(v) * f for v in lv.get("vmg_down", [None] * n)]
            ),
            race_pace=pace_t,
            pace_sd_log=None if sd_pace is None else float(sd_pace),
        )
    cells = blk.get("cells", {})
    status = np.asarray(cells.get("status", [["learned"] * n] * m), dtype=np.str_)
    if status.shape != shape or not np.isin(status, _STATUSES).all():
        raise InputError(
            f"{p}: {LEARNED_KEY}.cells.status: expected {shape} entries of " + ", ".join(_STATUSES)
        )
    default = str(blk.get("default_level", DEFAULT_LEVEL))
    ordered = {default: levels[default]} if default in levels else {}
    ordered.update({k: v for k, v in levels.items() if k != default})
    return LearnedPolar(
        name=base.name,
        twa_deg=base.twa_deg.copy(),
        tws_ms=base.tws_ms.copy(),
        levels=MappingProxyType(ordered),
        blocks=arr(cells, "blocks", f"{LEARNED_KEY}.cells").astype(np.int64),
        boats=arr(cells, "boats", f"{LEARNED_KEY}.cells").astype(np.int64),
        seconds=arr(cells, "seconds", f"{LEARNED_KEY}.cells"),
        status=status,
        reasons=tuple(str(x) for x in blk.get("refused", [])),
        verdict=tuple(str(x) for x in blk.get("verdict", [])),
        provenance=MappingProxyType(dict(blk.get("provenance", {}))),
    )


__all__ = ["LEARNED_KEY", "is_learned", "learned_to_dict", "read_learned", "write_learned"]
