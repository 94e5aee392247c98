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
    """

    tileset: TilesetSettings = field(default_factory=TilesetSettings)
    thumbnail: int = 256

    def for_photo(self, seed: int) -> TilesetSettings:
        """The tile-set settings of one photo: ``seed`` its own (the layout follows it unless
        a layout seed is fixed)."""
        return self.tileset.replace(seed=seed)

    def to_dict(self) -> dict:
        return {"tileset": self.tileset.to_dict(), "thumbnail": self.thumbnail}

    @classmethod
    def from_dict(cls, d: dict) -> BatchSettings:
        return cls(TilesetSettings.from_dict(d["tileset"]), int(d.get("thumbnail", 256)))

    def __reduce__(self):
        # sent to worker processes and Dask workers as plain data (a SeamSpec's options are a
        # read-only mapping, which pickle refuses)
        return (BatchSettings.from_dict, (self.to_dict(),))

    def digest(self) -> str:
        """A hash of these settings and of :data:`FOLDER_VERSION` (hex, 16 digits)."""
        doc = {"folder_version": FOLDER_VERSION, "settings": self.to_dict()}
        text = json.dumps(doc, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]
