"""sailroute: open, scriptable race routing for buoy courses.

The package is a functional core (``wind``, ``boat``, ``course``, ``routing``,
``strategy``) with thin orchestration (``plan``) and a thin CLI (``cli``).
Conventions (units, angles, time) are in ``docs/nomenclature.md``.
"""

from __future__ import annotations

__version__ = "0.1.0"

__all__ = ["__version__"]
