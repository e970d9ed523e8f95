"""Wind sources, all behind the :class:`~sailroute.wind.base.WindField` protocol."""

from sailroute.wind.base import Coverage, WindField, prepare_points

__all__ = ["Coverage", "WindField", "prepare_points"]
