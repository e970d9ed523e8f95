"""Planning: route a course leg by leg in its wind scenarios, and the results.

* :mod:`sailroute.planning.route` -- :func:`plan_course`, :func:`compare_scenarios`,
  :func:`route_course`, :class:`RunOptions`;
* :mod:`sailroute.planning.result` -- :class:`Plan`, :class:`PlannedLeg`,
  :class:`Comparison`, made from the routers' leg results.

Nothing here writes files or prints (:mod:`sailroute.commands.plan` does).
"""
