"""Validation helpers for wind specs (YAML mappings): collect every problem, then raise once.

Each problem names its key path, what was expected and what was found, e.g.
``courses/x.yaml: scenarios.wrf10[0].time_step_min: expected a positive number, got 'ten'``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from sailroute.errors import InputError, format_problems

_MISSING = object()


class SpecChecker:
    """Reads typed values from a spec mapping and records problems instead of raising.

    Parameters
    ----------
    where : str
        Prefix of every key path, e.g. ``"courses/x.yaml: scenarios.wrf10[0]"``.
    """

    def __init__(self, where: str) -> None:
        self.where = where
        self.problems: list[str] = []

    # -- paths and problems -----------------------------------------------------
    def path(self, key: str | int) -> str:
        """Key path of ``key`` below this checker's prefix."""
        if isinstance(key, int):
            return f"{self.where}[{key}]"
        if not self.where:
            return key
        if self.where.endswith(":"):
            return f"{self.where} {key}"
        return f"{self.where}.{key}"

    def child(self, key: str | int) -> SpecChecker:
        """A checker for a nested mapping that shares this checker's problem list."""
        c = SpecChecker(self.path(key))
        c.problems = self.problems
        return c

    def add(self, key: str | int, message: str) -> None:
        """Record a problem at ``key``."""
        self.problems.append(f"{self.path(key)}: {message}")

    def raise_if_any(self, what: str = "wind spec") -> None:
        """Raise one :class:`InputError` listing every recorded problem."""
        if not self.problems:
            return
        if len(self.problems) == 1:
            raise InputError(self.problems[0])
        n = len(self.problems)
        title = f"{self.where or what}: {n} problems in the {what}"
        raise InputError(format_problems(title, self.problems))

    # -- typed getters ----------------------------------------------------------
    def check_keys(
        self, spec: Mapping[str, Any], allowed: Iterable[str], required: Iterable[str] = ()
    ) -> None:
        """Record unknown keys (with the valid ones) and missing required keys."""
        allowed = list(allowed)
        for key in spec:
            if key not in allowed:
                hint = _close_match(str(key), allowed)
                self.add(
                    str(key),
                    "unknown key"
                    + (f" (did you mean {hint!r}?)" if hint else "")
                    + "; valid keys: "
                    + ", ".join(allowed),
                )
        for key in required:
            if key not in spec:
                self.add(key, "missing required key")

    def number(
        self,
        spec: Mapping[str, Any],
        key: str,
        default: Any = _MISSING,
        *,
        positive: bool = False,
        nonnegative: bool = False,
        lo: float | None = None,
        hi: float | None = None,
    ) -> Any:
        """A finite number (int/float, not bool), optionally constrained; ``default`` if absent."""
        if spec.get(key) is None:
            if default is _MISSING:
                self.add(key, "missing required key")
                return None
            return default
        value = spec[key]
        kind = "a positive number" if positive else (
            "a number >= 0" if nonnegative else "a number"
        )
        if lo is not None and hi is not None:
            kind = f"a number in [{lo:g}, {hi:g}]"
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(
            float(value)
        ):
            self.add(key, f"expected {kind}, got {value!r}")
            return None
        value = float(value)
        if (
            (positive and value <= 0)
            or (nonnegative and value < 0)
            or (lo is not None and value < lo)
            or (hi is not None and value > hi)
        ):
            self.add(key, f"expected {kind}, got {value!r}")
            return None
        return value

    def boolean(self, spec: Mapping[str, Any], key: str, default: bool) -> bool:
        """A YAML boolean (``true``/``false``)."""
        if key not in spec:
            return default
        value = spec[key]
        if not isinstance(value, bool):
            self.add(key, f"expected true or false, got {value!r}")
            return default
        return value

    def choice(
        self, spec: Mapping[str, Any], key: str, choices: Iterable[str], default: Any = _MISSING
    ) -> Any:
        """One of ``choices`` (strings)."""
        choices = list(choices)
        if key not in spec:
            if default is _MISSING:
                self.add(key, "missing required key; expected one of " + _quoted(choices))
                return None
            return default
        value = spec[key]
        if value not in choices:
            self.add(key, f"expected one of {_quoted(choices)}, got {value!r}")
            return None
        return value

    def string(self, spec: Mapping[str, Any], key: str, default: Any = _MISSING) -> Any:
        """A non-empty string."""
        if key not in spec:
            if default is _MISSING:
                self.add(key, "missing required key; expected a string")
                return None
            return default
        value = spec[key]
        if not isinstance(value, str) or not value.strip():
            self.add(key, f"expected a non-empty string, got {value!r}")
            return None
        return value

    def mapping(self, spec: Mapping[str, Any], key: str, default: Any = _MISSING) -> Any:
        """A nested mapping."""
        if key not in spec:
            if default is _MISSING:
                self.add(key, "missing required key; expected a mapping")
                return None
            return default
        value = spec[key]
        if not isinstance(value, Mapping):
            self.add(key, f"expected a mapping (key: value pairs), got {value!r}")
            return None
        return value


def _quoted(choices: list[str]) -> str:
    return ", ".join(repr(c) for c in choices)


def _close_match(key: str, allowed: list[str]) -> str | None:
    import difflib

    m = difflib.get_close_matches(key, allowed, n=1, cutoff=0.6)
    return m[0] if m else None
