"""The one result every command returns: what it printed, what it wrote, what it found."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["CommandResult"]


@dataclass(frozen=True, eq=False)
class CommandResult:
    """What a ``sailroute`` command prints and wrote.

    Attributes
    ----------
    report : str
        The terminal text (tables, summaries).
    files : mapping of str to Path
        Kind (``plan``, ``track``, ``gpx``, ``png``, ``json``, ...) -> path, in the order
        written.
    data : object
        The command's result object (a ``Plan``, ``Comparison``, ``TrackAnalysis`` tuple,
        ``StrategyResult``, ``VppRun``, ``FitRun``, ...), for callers of the Python API.
    notes : tuple of str
        Findings the run reports beside its tables (printed as ``note:`` lines).
    main : tuple of str
        The kinds in ``files`` whose file is the command's JSON document (``--json``
        prints the first one present).
    labels : mapping of str to str, optional
        Kind -> human name of the files (``wrote <name>: <path>``); None: the plan and
        analysis names (:data:`sailroute.report.files.FILE_LABELS`).
    """

    report: str
    files: Mapping[str, Path]
    data: Any = None
    notes: tuple[str, ...] = ()
    main: tuple[str, ...] = field(default=("json",))
    labels: Mapping[str, str] | None = None

    def main_json(self) -> Path | None:
        """The command's JSON document: the first of ``main`` written, else the first ``.json``.

        Returns
        -------
        Path or None
            None when the command wrote no JSON file.
        """
        for kind in self.main:
            if kind in self.files:
                return Path(self.files[kind])
        return next((Path(p) for p in self.files.values() if Path(p).suffix == ".json"), None)
