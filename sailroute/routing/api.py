"""One entry point for routing a leg: :func:`route_leg` dispatches on ``settings.router``.

=============  ===============================================  ==========================
router         function                                         module
=============  ===============================================  ==========================
``isochrone``  :func:`~sailroute.routing.isochrone.route_isochrone`  ``routing/isochrone.py``
``griddp``     ``route_griddp``                                 ``routing/griddp.py``
``spline``     ``route_spline``                                 ``routing/multispline.py``
=============  ===============================================  ==========================

All routers share the signature declared by :class:`Router`,
``(start, target, t0, wind, boat, settings, *, progress=None, xp=numpy, current=None,
obstacles=None) -> LegResult`` (``boat`` a :class:`~sailroute.boat.model.BoatModel`; ``xp``,
an array module, is passed by :func:`route_leg` only for a non-NumPy ``backend``;
``current`` and ``obstacles`` only when given, and only to a router whose
:class:`RouterEntry` supports them; a router that does not refuses them with a message
(:func:`check_router_supports`); each router module declares
``_ROUTER: Router = route_...`` so that mypy checks it) and
report through :func:`~sailroute.routing.track.make_leg_result`, so their results
compare directly.  The grid-DP and spline routers are imported only when asked for.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from sailroute.backend import get_xp
from sailroute.boat.model import BoatModel
from sailroute.errors import InputError, RoutingError
from sailroute.routing.geometry import leg_label, start_centre
from sailroute.routing.settings import (
    GridDPSettings,
    IsochroneSettings,
    RoutingSettings,
    SplineSettings,
)
from sailroute.routing.types import LegResult, Start, Target
from sailroute.wind.base import WindField

if TYPE_CHECKING:
    from sailroute.routing.obstacles import Obstacles
    from sailroute.wind.current import CurrentField


class Router(Protocol):
    """A leg router: the signature every routing function shares.

    ``(start, target, t0, wind, boat, settings, *, progress=None, xp=numpy, current=None,
    obstacles=None) -> LegResult`` (:mod:`sailroute.routing.api` lists the
    implementations and what each supports; each router module declares
    ``_ROUTER: Router = route_...`` so that mypy checks it against this).  ``current``
    is a surface current (:class:`~sailroute.wind.current.CurrentField`), ``obstacles`` the
    race area (:class:`~sailroute.routing.obstacles.Obstacles`); a router that cannot
    honour one refuses it with an :class:`~sailroute.errors.InputError`.
    """

    def __call__(
        self,
        start: Start,
        target: Target,
        t0: float,
        wind: WindField,
        boat: BoatModel,
        settings: RoutingSettings,
        /,
        *,
        progress: Callable[[float], None] | None = None,
        xp: ModuleType = ...,
        current: CurrentField | None = None,
        obstacles: Obstacles | None = None,
    ) -> LegResult:
        """Fastest route of one leg (see :func:`~sailroute.routing.api.route_leg`)."""
        ...


@dataclass(frozen=True)
class RouterEntry:
    """A registered router: where it lives and what it supports.

    Attributes
    ----------
    module, function : str
        The routing function ``module.function`` (imported when first asked for).
    settings_type : type
        Its settings class, the :class:`~sailroute.routing.settings.RoutingSettings`
        field named as the router (``settings.griddp`` is a
        :class:`~sailroute.routing.settings.GridDPSettings`).
    current : bool
        Routes a surface current (``current=`` keyword).
    obstacles : bool
        Honours a race-area boundary and obstacles (``obstacles=`` keyword).
    dynamic_boat : bool
        Routes a boat without a steady polar (the dynamic model).
    backends : tuple of str
        Array backends of its kernels (:func:`sailroute.backend.get_xp`).
    """

    module: str
    function: str
    settings_type: type[IsochroneSettings | GridDPSettings | SplineSettings]
    current: bool = False
    obstacles: bool = False
    dynamic_boat: bool = False
    backends: tuple[str, ...] = ("numpy", "cupy")


ROUTERS: dict[str, RouterEntry] = {
    "isochrone": RouterEntry(
        "sailroute.routing.isochrone",
        "route_isochrone",
        IsochroneSettings,
        current=True,
        obstacles=True,
    ),
    "griddp": RouterEntry(
        "sailroute.routing.griddp",
        "route_griddp",
        GridDPSettings,
        obstacles=True,
        dynamic_boat=True,
    ),
    "spline": RouterEntry(
        "sailroute.routing.multispline", "route_spline", SplineSettings, dynamic_boat=True
    ),
}
"""Router name -> :class:`RouterEntry`."""


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
    module_name, func_name = ROUTERS[name].module, ROUTERS[name].function
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


def check_router_supports(
    router: str,
    *,
    current: bool = False,
    obstacles: bool = False,
    dynamic_boat: bool = False,
) -> None:
    """Refuse what a course asks of a router that the router does not support.

    Parameters
    ----------
    router : str
        The router's name (see :data:`ROUTERS`).
    current, obstacles, dynamic_boat : bool
        Whether the course routes a surface current, a race-area boundary or
        obstacles, a boat without a steady polar.

    Raises
    ------
    InputError
        Naming the router, what it lacks, and the routers that have it.
    """
    entry = ROUTERS.get(router)
    if entry is None:
        get_router(router)  # raises the unknown-router message
        return
    wants = (
        (
            current,
            entry.current,
            "current",
            "a current is supported by the {who} router{s} only; set routing.router: {first} "
            "(or remove the scenario's `current:`)",
        ),
        (
            obstacles,
            entry.obstacles,
            "obstacles",
            "a race-area boundary or obstacles are honoured by the {who} router{s} only; set "
            "routing.router: {first} (or remove the course's `boundary:`/`obstacles:`)",
        ),
        (
            dynamic_boat,
            entry.dynamic_boat,
            "dynamic_boat",
            "a boat without a steady polar is routed by the {who} router{s} only; set "
            "routing.router: {first} (or give the boat a polar)",
        ),
    )
    for asked, has, attr, text in wants:
        if asked and not has:
            able = [k for k, e in ROUTERS.items() if getattr(e, attr)]
            who = " and ".join(repr(k).strip("'") for k in able)
            raise InputError(
                f"routing.router: {router!r}: "
                + text.format(
                    who=who, s="s" if len(able) > 1 else "", first=able[0] if able else "isochrone"
                )
            )


def check_current_router(router: str) -> None:
    """Refuse a surface current for a router that cannot route one
    (:func:`check_router_supports` with ``current=True``).

    Raises
    ------
    InputError
        For any router but ``isochrone``.
    """
    check_router_supports(router, current=True)


def _is_dynamic(boat: object) -> bool:
    """A boat model without a steady polar but with segment dynamics (the dynamic boat);
    anything else is left to the router's own check."""
    return (
        isinstance(boat, BoatModel) and boat.routing_polar() is None and boat.dynamics() is not None
    )


def _check_passage(obstacles: Obstacles, start: Start, target: Target) -> None:
    """Refuse a leg whose start and target lie in separate parts of free water."""
    name = obstacles.separated(start_centre(start), target.centre)
    if name is not None:
        from sailroute.routing.obstacles import constraint_label  # shapely: only with an area

        what = constraint_label(name)
        raise RoutingError(
            f"leg {leg_label(start, target)}: no route round {what}: the start and the "
            f"target lie in separate parts of free water ({obstacles.describe()}).\n  Try: "
            "leave a passage between the obstacles and the boundary wider than their "
            "clearances, or move the marks."
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
    obstacles: Obstacles | None = None,
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
        Surface current (:mod:`sailroute.wind.current`); only the routers whose
        :class:`RouterEntry` says so take one.
    obstacles : Obstacles, optional
        Race-area boundary and obstacles (:mod:`sailroute.routing.obstacles`); the
        route stays in free water.  Refused by a router that cannot honour them.

    Returns
    -------
    LegResult

    Raises
    ------
    InputError
        Unknown router or backend, invalid settings/geometry, or a current, obstacles
        or a dynamic boat given to a router that does not support them
        (:func:`check_router_supports`).
    RoutingError
        The router is not installed, or the leg cannot be routed (the message
        names the leg, why, and what to try).
    OutOfCoverageError
        The wind field does not cover the leg (propagated).
    """
    func = get_router(settings.router)
    xp = get_xp(backend)
    extra: dict[str, Any] = {} if xp is np else {"xp": xp}  # NumPy is every router's default
    check_router_supports(
        settings.router,
        current=current is not None,
        obstacles=obstacles is not None,
        dynamic_boat=_is_dynamic(boat),
    )
    if current is not None:
        extra["current"] = current
    if obstacles is not None:
        _check_passage(obstacles, start, target)
        extra["obstacles"] = obstacles
    try:
        return func(start, target, t0, wind, boat, settings, progress=progress, **extra)
    except RoutingError as exc:
        label = leg_label(start, target)
        if f"leg {label}" in str(exc):
            raise
        raise RoutingError(f"leg {label} ({settings.router} router): {exc}") from exc
