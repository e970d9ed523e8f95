"""Race analysis core (pure functions): leg segmentation, manoeuvre detection, loss split.

* :mod:`sailroute.analysis.segment`: start, mark roundings, gate and line crossings;
* :mod:`sailroute.analysis.manoeuvres`: tacks and gybes from the sign of TWA;
* :mod:`sailroute.analysis.loss`: progress, sides, and the loss decomposition.

The orchestration is :func:`sailroute.analyze.analyze_track`.
"""
