"""Which wind a sailed leg is judged in: the boat's measured wind, the fleet's, or a scenario.

A race analysis is only as good as its wind.  ``analyze`` takes an ordered list of
candidate fields (:class:`WindSource`), best first, and for each leg uses the first
one that covers the whole leg (its sailed points and the optimal route from the leg
start).  The usual order, :func:`wind_order`:

1. ``measured``: the boat's own instruments (TWS/TWD, or apparent wind converted to
   true), a field uniform in space that follows the log in time, with holes where the
   log has gaps;
2. ``fleet``: the wind measured by the other boats of the run, as one field in space
   and time (boats' biases removed);
3. ``inferred``: the wind rebuilt from the fleet's GPS tracks (tack and gybe headings,
   upwind and downwind courses), for tracks without instruments;
4. ``scenario``: the course's scenario (a sailor's estimate or a forecast).

Every output names the source of each leg.  Nothing here reads files.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from sailroute.errors import InputError, OutOfCoverageError
from sailroute.wind.base import WindField

KINDS: Final = ("measured", "fleet", "inferred", "scenario")
"""Kinds of wind source, in the order ``auto`` tries them."""

CHOICES: Final = ("auto", "measured", "inferred", "scenario")
"""Values of ``analyze --wind``: ``auto`` takes the best available per leg."""

MEASURED_TWD_SD_DEG: Final = 4.0
"""Standard error of a measured TWD at one instant [°]: three SailGP boats' logged TWD
(Auckland 2025, smoothed 30 s) differ pairwise by 3.4-8.0° RMS."""

ABOVE_POLAR_PCT: Final = 110.0
"""A leg sailed above this mean polar percentage is flagged: the polar (a stand-in for
another class?) or the wind (too light?) cannot be right [%]."""


@dataclass(frozen=True, eq=False)
class WindSource:
    """One candidate wind for judging a track.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    field : WindField
        The wind.
    label : str
        What it is, for reports ("measured on board (TWS/TWD columns)",
        "scenario 'constant'").
    route_field : WindField, optional
        The same wind with its holes bridged, for the routers: their look-ahead samples
        the wind along the way to the target far beyond the route's own time, and a
        hole there says nothing about the route.  The routed track itself is then
        checked against :attr:`field` (:func:`route_covered`).
    twd_sd : callable, optional
        The standard error of the direction at a time [epoch s -> °] (an inferred wind's);
        None: the kind's (:meth:`twd_sd_at`).
    """

    kind: str
    field: WindField
    label: str
    route_field: WindField | None = None
    twd_sd: Callable[[float], float] | None = None

    def twd_sd_at(self, t: float) -> float:
        """Standard error of the direction at ``t`` [°]: :attr:`twd_sd`'s, else
        ``MEASURED_TWD_SD_DEG`` for a measured wind and 0 for a scenario (the wind the
        course was laid in)."""
        if self.twd_sd is not None:
            return float(self.twd_sd(t))
        return MEASURED_TWD_SD_DEG if self.kind in ("measured", "fleet") else 0.0

    @property
    def for_routing(self) -> WindField:
        """The field a router samples (:attr:`route_field`, else :attr:`field`)."""
        return self.route_field if self.route_field is not None else self.field

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"WindSource.kind {self.kind!r}; expected one of {KINDS}")


def wind_order(choice: str, available: Sequence[WindSource]) -> list[WindSource]:
    """The candidates for ``analyze --wind CHOICE``, best first.

    Parameters
    ----------
    choice : str
        One of :data:`CHOICES`.  ``auto``: every available source in :data:`KINDS`
        order; ``measured``: the boat's own then the fleet's measured wind;
        ``inferred``: the track-inferred wind; ``scenario``: the course's.
    available : sequence of WindSource
        What could be built for this boat.

    Raises
    ------
    InputError
        Unknown choice, or nothing of the requested kind available (the message
        says what the data lack).
    """
    if choice not in CHOICES:
        raise InputError(f"--wind: expected one of {', '.join(CHOICES)}; got {choice!r}")
    wanted = {
        "auto": KINDS,
        "measured": ("measured", "fleet"),
        "inferred": ("inferred",),
        "scenario": ("scenario",),
    }[choice]
    out = sorted((s for s in available if s.kind in wanted), key=lambda s: KINDS.index(s.kind))
    if not out:
        why = {
            "measured": "no track has usable wind columns (tws/twd, twa with a heading, "
            "or aws/awa with a heading and boat speed)",
            "inferred": "the wind could not be inferred from the tracks (too few tacks "
            "and steady boards)",
            "scenario": "the course has no scenario",
        }.get(choice, "no wind source")
        raise InputError(f"--wind {choice}: {why}; use --wind auto or --wind scenario")
    return out


def covers(field: WindField, t: NDArray, x: NDArray, y: NDArray) -> bool:
    """True when ``field`` can be sampled at every point ``(t, x, y)`` (no hole, no edge)."""
    try:
        u, v = field.sample(t, x, y)
    except OutOfCoverageError:
        return False
    return bool(np.all(np.isfinite(u)) and np.all(np.isfinite(v)))


def first_covering(
    sources: Sequence[WindSource], t: NDArray, x: NDArray, y: NDArray, skip: int = -1
) -> int | None:
    """Index of the first source (after ``skip``) that covers all points, or None."""
    for k in range(skip + 1, len(sources)):
        if covers(sources[k].field, t, x, y):
            return k
    return None


__all__ = [
    "ABOVE_POLAR_PCT",
    "CHOICES",
    "KINDS",
    "MEASURED_TWD_SD_DEG",
    "WindSource",
    "covers",
    "first_covering",
    "wind_order",
]
