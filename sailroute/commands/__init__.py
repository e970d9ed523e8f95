"""The commands: each ``run_*_command`` loads its inputs, calls the library and writes files.

Every command returns one :class:`~sailroute.commands.result.CommandResult`; ``cli.py``
only parses options and prints it.  The layers below (``wind``, ``boat``, ``course``,
``routing``, ``analysis``, ``strategy``, ``report``) never import this package.
"""

from sailroute.commands.result import CommandResult

__all__ = ["CommandResult"]
