"""Project files (``.quiltproj``): one zip holding ``project.json`` and PNG images.

The project is plain data (:class:`Project` holding :class:`engine.candidate.CandidateTile`
values, the engine's own), no Qt; the editor maps its
document to it and the CLI writes and reads the same file. Images come back as float32
(H, W, C) in [0, 1] at the bits they were saved with.

Modules, one job each: :mod:`~engine.project.model` (the data), :mod:`~engine.project.checks`
(cross-field consistency), :mod:`~engine.project.build` (a project from a tile set's arrays),
:mod:`~engine.project.document` (``project.json``), :mod:`~engine.project.archive` (the zip on
disk: atomic saving, loading that trusts nothing, recovery files) and
:mod:`~engine.project.bundle` (exporting a project).
"""

from engine.project.archive import (
    MAX_DECODED_BYTES,
    ProjectError,
    load_project,
    newer_recovery,
    recovery_path,
    save_project,
)
from engine.project.build import project_from_tileset
from engine.project.bundle import export_project
from engine.project.model import (
    PROJECT_FORMAT,
    PROJECT_SUFFIX,
    PROJECT_VERSION,
    Project,
)

__all__ = [
    "MAX_DECODED_BYTES",
    "PROJECT_FORMAT",
    "PROJECT_SUFFIX",
    "PROJECT_VERSION",
    "Project",
    "ProjectError",
    "export_project",
    "load_project",
    "newer_recovery",
    "project_from_tileset",
    "recovery_path",
    "save_project",
]
