"""Leg-time bands: P10/P50/P90 of each leg and of the race from stated uncertainties.

:mod:`sailroute.bands.members` turns a course's ``uncertainty`` section
(:mod:`sailroute.course.uncertainty`) into members (a wind speed change, a direction
offset, a shift in time, race-polar parameters), deterministic for a seed; how the
members are routed is up to the caller (``sailroute.bands.route.route_members``
routes them one by one); :mod:`sailroute.bands.summary` gives the bands, the
one-at-a-time breakdown by source and the side verdicts.  The submodules are imported
by their full names (this package imports nothing).
"""
