"""The names quilting's options take (no numpy: the command line's parsers read them)."""

from engine.seams.spec import METHODS, STRAIGHT

SELECTIONS = ("best", "random", "sampled", "bhatia")
MODES = ("auto", "exact", "fast")
SEAMS = (STRAIGHT, *METHODS)
CORRESPONDENCES = ("luminance", "blurred")
"""Texture transfer's correspondence maps (:mod:`engine.transfer`)."""

__all__ = ["CORRESPONDENCES", "MODES", "SEAMS", "SELECTIONS"]
