"""The package version, in a module of its own that imports nothing.

Modules anywhere in the package (the output folders' manifest, the pages, the route
exports, the command line) read it from here, so none of them imports the package root,
which loads the public API (and through it the report layer) lazily.
"""

__version__ = "0.1.0"
