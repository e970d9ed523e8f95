"""One entry point for routing a leg: :func:`route_leg` dispatches on ``settings.router``.

=============  ===============================================  ==========================
router         function                                         module
=============  ===============================================  ==========================
``isochrone``  :func:`~sailroute.routing.isochrone.route_isochrone`  ``routing/isochrone.py``
``griddp``     ``route_griddp``                                 ``routing/griddp.py``
``spline``     ``route_spline``                                 ``routing/multispline.py``
=============  ===============================================  ==========================

All routers share the signature declared by :class:`~sailroute.routing.types.Router`,
``(start, target, t0, wind, boat, settings, *, progress=None, xp=numpy) -> LegResult``
(``boat`` a :class:`~sailroute.boat.model.BoatModel`; ``xp``, an array module, is passed by
:func:`route_leg` only for a non-NumPy ``backend``; each router module declares
``_ROUTER: Router = route_...`` so that mypy checks it) and
report through :func:`~sailroute.routing.track.make_leg_result`, so their results
compare directly.  The grid-DP and spline routers are imported only when asked for.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

import numpy as np

from sailroute.backend import get_xp
from sailroute.boat.model import BoatModel
from sailroute.errors import InputError, RoutingError
from sailroute.routing.geometry import leg_label
from sailroute.routing.types import LegResult, Router, RoutingSettings, Start, Target
from sailroute.wind.base import WindField

ROUTERS: dict[str, tuple[str, str]] = {
    "isochrone": ("sailroute.routing.isochrone", "route_isochrone"),
    "griddp": ("sailroute.routing.griddp", "route_griddp"),
    "spline": ("sailroute.routing.multispline", "route_spline"),
}
"""Router name -> (module, function)."""


def get_router(name: str) -> Router:
    """The routing function registered under ``name``.

    Raises
    ------
    InputError
        For an unknown name (the message lists the valid ones).
    RoutingError
        If the router's module is not part of this installation.
    """
    if name not in ROUTERS:
        raise InputError(
            f"routing.router: unknown router {name!r}; expected one of "
            + ", ".join(repr(k) for k in ROUTERS)
        )
    module_name, func_name = ROUTERS[name]
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name != module_name:
            raise
        raise RoutingError(
            f"router {name!r} is not available: module {module_name} is missing from this "
            "installation. Use router 'isochrone', or install a sailroute version that "
            f"ships {module_name}."
        ) from None
    func: Router | None = getattr(module, func_name, None)
    if func is None:
        raise RoutingError(
            f"router {name!r} is not available: {module_name} has no function {func_name}. "
            "Use router 'isochrone'."
        )
    return func


def check_current_router(router: str) -> None:
    """Refuse a surface current for a router that cannot route one.

    Raises
    ------
    InputError
        For any router but ``isochrone``.
    """
    if router != "isochrone":
        raise InputError(
            f"routing.router: {router!r}: a current is supported by the isochrone router "
            "only; set routing.router: isochrone (or remove the scenario's `current:`)"
        )


def route_leg(
    start: Start,
    target: Target,
    t0: float,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    *,
    progress: Callable[[float], None] | None = None,
    backend: str = "numpy",
    current: Any = None,
) -> LegResult:
    """Fastest route of one leg with the router chosen in ``settings.router``.

    Parameters
    ----------
    start : Start
        Start point or start line.
    target : Target
        Mark (with rounding side), gate or line.
    t0 : float
        Start time [epoch s].
    wind : WindField
        Wind field.
    boat : BoatModel
        Boat performance: a :class:`~sailroute.boat.polar.Polar` (every router) or a
        :class:`~sailroute.boat.dynamic.DynamicBoat` (grid DP and spline routers).
    settings : RoutingSettings
        Router choice and numerical settings.
    progress : callable, optional
        Receives the estimated fraction done, in [0, 1].
    backend : {"numpy", "cupy", "auto"}
        Array backend of the router's data-parallel kernels
        (:func:`sailroute.backend.get_xp`); results agree within float tolerance.
    current : CurrentField, optional
        Surface current (:mod:`sailroute.wind.current`); only the isochrone router takes one.

    Returns
    -------
    LegResult

    Raises
    ------
    InputError
        Unknown router or backend, or invalid settings/geometry.
    RoutingError
        The router is not installed, or the leg cannot be routed (the message
        names the leg, why, and what to try).
    OutOfCoverageError
        The wind field does not cover the leg (propagated).
    """
    func = get_router(settings.router)
    xp = get_xp(backend)
    extra = {} if xp is np else {"xp": xp}  # NumPy is every router's default
    if current is not None:
        check_current_router(settings.router)
        extra["current"] = current
    try:
        return func(start, target, t0, wind, boat, settings, progress=progress, **extra)
    except RoutingError as exc:
        label = leg_label(start, target)
        if f"leg {label}" in str(exc):
            raise
        raise RoutingError(f"leg {label} ({settings.router} router): {exc}") from exc
