"""What a router needs from a boat: the :class:`BoatModel` protocol.

Two boat models implement it:

* :class:`~sailroute.boat.polar.Polar`: a steady polar table (boat speed is a function
  of TWS and TWA only);
* :class:`~sailroute.boat.dynamic.DynamicBoat`: Dębski's segment dynamics, where the
  speed also depends on the speed carried into a segment.

Routers never ask a boat what class it is: they call :meth:`BoatModel.routing_polar`
(the steady polar a polar router samples, or None) and :meth:`BoatModel.dynamics` (the
momentum model the grid routers carry between segments, or None).
``tests/boat/test_boat_model.py`` checks both implementations against this contract.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    from sailroute.boat.dynamic import DynamicBoat
    from sailroute.boat.polar import Polar


@runtime_checkable
class BoatModel(Protocol):
    """Protocol of the boat models the routers take (see the module docstring)."""

    @property
    def name(self) -> str:
        """Label for reports."""
        ...

    def steady_speed(self, tws_ms: ArrayLike, twa_deg: ArrayLike) -> NDArray[np.float64]:
        """Steady boat speed [m s⁻¹] at TWS [m s⁻¹] and TWA [°] (broadcast; sign of TWA
        ignored)."""
        ...

    def vmg_angles_deg(self, tws_ms: float) -> tuple[float, float]:
        """Upwind and downwind best-VMG |TWA| [°] at ``tws_ms`` [m s⁻¹]."""
        ...

    def routing_polar(self) -> Polar | None:
        """The steady polar a polar router (isochrone) samples: a :class:`Polar` is its
        own; None for a boat whose speed depends on its history (the dynamic model)."""
        ...

    def dynamics(self) -> DynamicBoat | None:
        """The segment-dynamics model the grid routers carry momentum with; None for a
        boat with steady speeds only (a :class:`Polar`)."""
        ...
