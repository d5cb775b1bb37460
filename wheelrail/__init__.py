"""wheelrail: the thin front (CLI, scene and case files, output folders). No physics here."""

__version__ = "0.1.0"
