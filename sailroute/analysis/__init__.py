"""Race analysis core (pure functions): leg segmentation, manoeuvre detection, loss split.

* :mod:`sailroute.analysis.segment`: start, mark roundings, gate and line crossings;
* :mod:`sailroute.analysis.manoeuvres`: tacks and gybes from the sign of TWA;
* :mod:`sailroute.analysis.loss`: progress, sides, and the loss decomposition;
* :mod:`sailroute.analysis.infer_wind`: TWD(t) (and TWS(t) with a polar) inferred from
  GPS tracks without instruments.

The orchestration is :func:`sailroute.analysis.debrief.analyze_track`.
"""
