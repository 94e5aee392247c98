"""Bundled sample textures and icons (see README.md for origins and licenses)."""

from importlib.resources import files
from pathlib import Path

SAMPLE_NAMES = ("brick", "grass", "gravel", "cobblestones", "lichen")
DEFAULT_SAMPLE = "cobblestones"


def sample_path(name: str = DEFAULT_SAMPLE) -> Path:
    """Filesystem path of a bundled sample texture."""
    if name not in SAMPLE_NAMES:
        raise ValueError(f"unknown sample {name!r}; choose from {', '.join(SAMPLE_NAMES)}")
    return Path(str(files("resources") / "samples" / f"{name}.png"))


def icon_path() -> Path:
    """Filesystem path of the application icon (PNG)."""
    return Path(str(files("resources") / "icons" / "quilt-studio.png"))
