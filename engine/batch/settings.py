"""What a batch makes of every photo, and the hash that says whether a folder is up to date."""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field

from engine.settings import TilesetSettings

#: Bumped when the content of a photo folder changes for the same settings (so a re-run
#: redoes the photos made by an older layout of the folder).
FOLDER_VERSION = 1


@dataclass(frozen=True, slots=True)
class BatchSettings:
    """The options that decide a photo folder's content (never how it is computed: the number
    of workers or the scheduler are not here, and do not change a byte of the result).

    ``tileset``: the tile-set workflow's settings (the ``tileset`` command's and the
    editor's), a Wang set when ``tileset.wang`` is set; its ``seed`` is the batch seed, mixed
    with each photo's content digest (:func:`engine.batch.inputs.photo_seed`).
    ``thumbnail``: the longer side of the 8x8 preview's thumbnail in px.
    ``tile_size_auto``: a Wang set's tile size moved, per photo, to one that holds whole
    periods of its texture (the ``tileset`` command's ``--tile-size auto``).
    """

    tileset: TilesetSettings = field(default_factory=TilesetSettings)
    thumbnail: int = 256
    tile_size_auto: bool = False

    def for_photo(self, seed: int) -> TilesetSettings:
        """The tile-set settings of one photo: ``seed`` its own (the layout follows it unless
        a layout seed is fixed)."""
        return self.tileset.replace(seed=seed)

    def to_dict(self) -> dict:
        d = {"tileset": self.tileset.to_dict(), "thumbnail": self.thumbnail}
        if self.tile_size_auto:  # only when set: the libraries made before keep their hash
            d["tile_size_auto"] = True
        return d

    @classmethod
    def from_dict(cls, d: dict) -> BatchSettings:
        return cls(
            TilesetSettings.from_dict(d["tileset"]),
            int(d.get("thumbnail", 256)),
            bool(d.get("tile_size_auto", False)),
        )

    def __reduce__(self):
        # sent to worker processes and Dask workers as plain data (a SeamSpec's options are a
        # read-only mapping, which pickle refuses)
        return (BatchSettings.from_dict, (self.to_dict(),))

    def digest(self) -> str:
        """A hash of these settings and of :data:`FOLDER_VERSION` (hex, 16 digits)."""
        doc = {"folder_version": FOLDER_VERSION, "settings": self.to_dict()}
        text = json.dumps(doc, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]
