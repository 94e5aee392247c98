"""Opening and saving: images, projects, material maps, the transfer target, recent files,
autosave and crash recovery; the quilting output and the seamless tile as image files.

:class:`ProjectFiles` does the file work of the main window: reads and writes run as
background jobs, errors become messages (:attr:`ProjectFiles.message`), never tracebacks.
The only questions it asks (unsaved changes, file names) are methods tests replace
(:meth:`ProjectFiles.ask_save_changes`, :meth:`ProjectFiles.ask_open_path`,
:meth:`ProjectFiles.ask_save_path`).
"""

from __future__ import annotations

import os
from functools import partial
from pathlib import Path

from PySide6.QtCore import QObject, QSettings, QTimer, Signal, Slot
from PySide6.QtWidgets import QFileDialog, QMenu, QMessageBox

from engine.io import READ_SUFFIXES, ImageError, load_image
from engine.materials import infer_kind
from engine.project import (
    PROJECT_SUFFIX,
    ProjectError,
    load_project,
    newer_recovery,
    recovery_path,
    save_project,
)
from quilt_gui import jobs, params, project_io, settings
from quilt_gui.imaging import prepare_display
from quilt_gui.jobs import error_text
from quilt_gui.model import Source, safe_name
from resources import sample_path

IMAGE_FILTER = "Images (" + " ".join(f"*{s}" for s in READ_SUFFIXES) + ")"
SAVE_FILTER = "PNG (*.png);;TIFF (*.tif *.tiff);;JPEG (*.jpg);;WebP (*.webp);;BMP (*.bmp)"
PROJECT_FILTER = f"Quilt Studio projects (*{PROJECT_SUFFIX})"
OPEN_FILTER = (
    "Images and projects (" + " ".join(f"*{s}" for s in (*READ_SUFFIXES, PROJECT_SUFFIX)) + ")"
)
MAIN_MAP = "albedo"

#: Pillow's colour-model names (engine.io LoadedImage.mode) as the user reads them.
MODE_NAMES = {
    "L": "gray",
    "LA": "gray + alpha",
    "1": "black-and-white",
    "P": "palette",
    "PA": "palette + alpha",
    "RGBA": "RGB + alpha",
    "F": "gray (float)",
}


def mode_text(mode: str) -> str:
    return MODE_NAMES.get(mode, mode)


def read_image(path: str):
    """Worker: load an image and prepare its display copy (the GUI thread only copies it)."""
    loaded = load_image(path)
    prepare_display(loaded.pixels)
    return loaded


def read_project(path: str):
    """Worker: load a project and prepare the display copy of its main map."""
    project = load_project(path)
    if project.sources:
        prepare_display(next(iter(project.sources.values())))
    return project


HIGH_DEPTH = (".png", ".tif", ".tiff")  # formats that keep 16 bits


def save_image(path, image, *, bit_depth: int, source_bit_depth: int):
    """Worker: write one image (dithered when a 16-bit source is written at 8 bits)."""
    from engine.bitdepth import quantize
    from engine.io import save_image as write

    if bit_depth < source_bit_depth:
        image = quantize(image, bit_depth, dither=True, rng=0)
    return write(path, image, bit_depth=bit_depth)


def _export_seamless(path, maps, *, bit_depth: int, source_bit_depth: int):
    from engine.export.seamless import export_seamless

    return export_seamless(maps, path, bit_depth=bit_depth, source_bit_depth=source_bit_depth)


def default_folder(doc, key: str) -> str:
    """Where a file dialog starts (the same rule for saving and exporting): the folder last
    used for this kind of file (settings ``key``), else the source's folder, else the
    project's, else the home folder."""
    for folder in (
        settings.get(key),
        str(Path(doc.source.path).parent) if doc.source is not None and doc.source.path else "",
        str(Path(doc.project_path).parent) if doc.project_path else "",
    ):
        if folder and Path(folder).is_dir():
            return folder
    return str(Path.home())


def recovery_dir() -> Path:
    """Folder of the untitled-project recovery file (next to the settings file)."""
    return Path(QSettings().fileName()).parent / "recovery"


class ProjectFiles(QObject):
    """The file side of the editor for ``doc``; ``parent`` is the window dialogs belong to."""

    #: (level, text, actions): a message for the window's banner; ``actions`` are
    #: (label, callable) buttons
    message = Signal(str, str, object)
    image_opened = Signal()  # a new source image is in the document
    wang_opened = Signal()  # a project that holds a Wang set and no tile set: show its tab

    def __init__(self, doc, manager: jobs.JobManager, parent) -> None:
        super().__init__(parent)
        self.doc = doc
        self.jobs = manager
        self.closing = False
        #: sizes made smaller for the last image: key -> (the value before, the fitted one)
        self._fitted: dict[str, tuple] = {}
        self.autosave_timer = QTimer(self)
        self.autosave_timer.setInterval(max(5, settings.get("autosave_seconds")) * 1000)
        self.autosave_timer.timeout.connect(self.autosave_now)
        self.autosave_timer.start()

    def _say(self, level: str, text: str, actions=()) -> None:
        self.message.emit(level, text, actions)

    # ------------------------------------------------------------------ questions (patchable)
    def ask_save_changes(self) -> str:
        """ "save", "discard" or "cancel" for unsaved changes (tests replace this)."""
        output = " (and its quilting output)" if self.doc.quilting.unsaved else ""
        box = QMessageBox(
            QMessageBox.Icon.Warning,
            settings.APP_NAME,
            f"Save the changes to “{self.doc.name}”{output} before closing?",
            QMessageBox.StandardButton.Save
            | QMessageBox.StandardButton.Discard
            | QMessageBox.StandardButton.Cancel,
            self.parent(),
        )
        box.setDefaultButton(QMessageBox.StandardButton.Save)
        answer = box.exec()
        return {
            QMessageBox.StandardButton.Save: "save",
            QMessageBox.StandardButton.Discard: "discard",
        }.get(QMessageBox.StandardButton(answer), "cancel")

    def ask_open_path(self, caption: str, filters: str, key: str) -> str:
        path, _ = QFileDialog.getOpenFileName(self.parent(), caption, settings.get(key), filters)
        return path

    def ask_library_path(self) -> str:
        """A library folder made by ``quilt-studio batch`` ("" when cancelled)."""
        path = QFileDialog.getExistingDirectory(
            self.parent(), "Open library", settings.get("last_library_dir")
        )
        if path:
            settings.set("last_library_dir", path)
        return path

    def ask_save_path(self) -> str:
        start = self.doc.project_path or os.path.join(
            self.default_folder("last_project_dir"), self.doc.name + PROJECT_SUFFIX
        )
        path, _ = QFileDialog.getSaveFileName(self.parent(), "Save project", start, PROJECT_FILTER)
        if path and not path.endswith(PROJECT_SUFFIX):
            path += PROJECT_SUFFIX
        return path

    def ask_image_path(self, caption: str, name: str) -> str:
        """A file to write an image to (PNG by default), starting beside the source."""
        start = os.path.join(self.default_folder("last_export_dir"), name)
        path, _ = QFileDialog.getSaveFileName(self.parent(), caption, start, SAVE_FILTER)
        if path and not Path(path).suffix:
            path += ".png"
        return path

    def may_replace_output(self) -> bool:
        """True when a new quilting run may replace the output (none unsaved, or the user
        discards it)."""
        return not self.doc.quilting.unsaved or self.ask_discard_output()

    def ask_discard_output(self) -> bool:
        """True when the unsaved quilting output may be replaced (tests replace this)."""
        answer = QMessageBox.question(
            self.parent(),
            settings.APP_NAME,
            "The quilting output is not saved. Replace it by a new one?",
            QMessageBox.StandardButton.Discard | QMessageBox.StandardButton.Cancel,
            QMessageBox.StandardButton.Cancel,
        )
        return answer == QMessageBox.StandardButton.Discard

    def default_folder(self, key: str) -> str:
        return default_folder(self.doc, key)

    def confirm_discard(self) -> bool:
        """True when the current work may be replaced (saved, discarded or unchanged)."""
        if not self.doc.modified or not self.doc.has_source:
            return True
        answer = self.ask_save_changes()
        if answer == "save":
            return self.save(wait=True)
        return answer == "discard"

    # ------------------------------------------------------------------ opening
    def open_initial(self, path: str | None) -> None:
        """Start-up: open ``path`` (image or project) or the bundled sample; offer recovery."""
        untitled = recovery_dir() / f"untitled.recovery{PROJECT_SUFFIX}"
        if path:
            self.open_path(path, confirm=False)
        else:
            self.open_path(str(sample_path()), confirm=False, remember=False)
        if untitled.is_file():
            self.offer_recovery(untitled)

    def open_dialog(self) -> None:
        path = self.ask_open_path(
            "Open image or project",
            f"{OPEN_FILTER};;{IMAGE_FILTER};;{PROJECT_FILTER};;All files (*)",
            "last_open_dir",
        )
        if path:
            self.open_path(path)

    def open_sample(self, name: str, *_checked) -> None:
        self.open_path(str(sample_path(name)), remember=False)

    def open_path(self, path: str, *, confirm: bool = True, remember: bool = True) -> None:
        """Open an image or a ``.quiltproj`` in the background (errors become messages)."""
        path = os.fspath(path)
        if confirm and not self.confirm_discard():
            return
        if path.lower().endswith(PROJECT_SUFFIX):
            self._read("open", read_project, path, self._on_project_loaded)
        else:
            self._read("open", read_image, path, partial(self._on_image_loaded, remember=remember))

    def _read(self, key: str, reader, path: str, on_done) -> None:
        """Run ``reader(path)`` in the background; ``on_done(path, result)``; errors -> message."""
        self.jobs.start(
            key,
            reader,
            path,
            label=f"Opening {Path(path).name}",
            pass_cancel=False,
            on_done=partial(on_done, path),
            on_error=partial(self._on_open_error, path),
        )

    def _on_image_loaded(self, path: str, loaded, *, remember: bool) -> None:
        source = Source(
            maps={MAIN_MAP: loaded.pixels},
            paths={MAIN_MAP: loaded.path},
            bit_depth=loaded.bit_depth,
            kinds={MAIN_MAP: "color"},
        )
        self.doc.set_source(source)
        note = self._fit_parameters(loaded.pixels.shape)
        self._remember(path, "last_open_dir", remember)
        h, w = loaded.pixels.shape[:2]
        caveats = "".join(f"{n[0].upper()}{n[1:]}. " for n in loaded.notes)
        self._say(
            "warning" if caveats else "info",
            f"{caveats}Opened {Path(path).name}: {w}×{h}, {loaded.bit_depth}-bit "
            f"{mode_text(loaded.mode)}. {note}Next: Find best tile (Ctrl+T) or draw the "
            "tile rectangle.",
        )
        self.image_opened.emit()

    def _fit_parameters(self, shape) -> str:
        """Sizes left from a larger image go back to Auto, or (the block size, which has no
        Auto) down to what fits; sizes made smaller for the last image and not changed since
        come back first (a 40×30 photo must not leave 15 px blocks to the next one). Not an
        undo step: a new image starts a new history. Returns a sentence saying what, or ""."""
        p = self.doc.params
        back = {k: old for k, (old, fitted) in self._fitted.items() if p.get(k) == fitted}
        self._fitted = {}
        if back:
            self.doc.apply_params(back)
        changes = params.fit_to_source(self.doc.params, shape)
        self._fitted = {k: (p[k], v) for k, v in changes.items()}
        if changes:
            self.doc.apply_params(changes)
        label = params.BY_KEY
        auto = [k for k, v in changes.items() if v in (0, params.AUTO)]
        smaller = [f"{label[k].label} {p[k]} px" for k in changes if k not in auto]
        again = [f"{label[k].label} {v}" for k, v in back.items() if k not in changes]
        parts = []
        if auto:
            names = ", ".join(label[k].label for k in auto)
            parts.append(f"{names}: too large for this image, back to automatic. ")
        if smaller:
            parts.append(f"{', '.join(smaller)}: the image is too small for more. ")
        if again:
            parts.append(f"{', '.join(again)} again (made smaller for the last image). ")
        return "".join(parts)

    def _on_project_loaded(self, path: str, project) -> None:
        self._fitted = {}  # the project's own sizes
        project_io.apply_project(self.doc, project, path)
        self._remember(path, "last_project_dir", True)
        w, ts = self.doc.wang, self.doc.tileset
        wang = f": a Wang set of {len(w.tiles)} tiles (Wang tiles tab)" if w.tiles else ""
        self._say("info", f"Opened project {Path(path).name}{wang}.")
        if w.tiles and ts.template_rect is None and not ts.candidates:
            self.wang_opened.emit()  # all it holds is on that tab
        rec = newer_recovery(path)
        if rec is not None:
            self.offer_recovery(rec)

    def _on_open_error(self, path: str, exc) -> None:
        if isinstance(exc, (ImageError, ProjectError)):
            text = error_text(exc)
        else:
            text = f"{path}: cannot be opened ({error_text(exc)})"
        self._say("error", f"Could not open the file. {text}")

    def _remember(self, path: str, dir_key: str, recent: bool) -> None:
        settings.set(dir_key, str(Path(path).parent))
        if recent:
            settings.add_recent_file(str(Path(path).resolve()))

    def fill_recent_menu(self, menu: QMenu) -> None:
        menu.clear()
        files = settings.get("recent_files")
        if not files:
            a = menu.addAction("(none)")
            a.setEnabled(False)
            return
        for i, f in enumerate(files):
            a = menu.addAction(f"&{(i + 1) % 10} {Path(f).name}")
            a.setToolTip(f)
            a.setStatusTip(f)
            a.triggered.connect(partial(self.open_recent, f))
        menu.addSeparator()
        menu.addAction("Clear list", self._clear_recent)

    @Slot()
    def _clear_recent(self) -> None:
        settings.set("recent_files", [])

    def open_recent(self, path: str, *_checked) -> None:
        if not Path(path).exists():
            settings.remove_recent_file(path)
            self._say("error", f"{path} no longer exists; removed from the recent files.")
            return
        self.open_path(path)

    # ------------------------------------------------------------------ material maps, target
    def attach_dialog(self) -> None:
        path = self.ask_open_path("Attach material map", IMAGE_FILTER, "last_open_dir")
        if path:
            self.attach_map(path)

    def attach_map(self, path: str) -> None:
        """Load ``path`` as a material map of the source (kind guessed from its name)."""
        if not self.doc.has_source:
            self._say("warning", "Open a source image before attaching material maps.")
            return
        self._read("attach", load_image, path, self._on_map_loaded)

    def _on_map_loaded(self, path: str, loaded) -> None:
        kind = infer_kind(Path(path).stem)
        name = kind if kind not in ("color", "other") else safe_name(Path(path).stem).lower()
        base, k = name, 2
        while name in self.doc.source.maps:
            name, k = f"{base}{k}", k + 1
        try:
            self.doc.attach_map(name, loaded.pixels, path, kind)
        except ValueError as exc:
            self._say("error", str(exc))
            return
        text = (
            f"Attached {Path(path).name} as the “{name}” map ({kind}); it follows every cut of "
            "the tile set, the Wang set and Heal (quilting makes the colour map only)."
        )
        made = [  # made before it, without it: the project keeps only what has every map
            f"{n} {what}"
            for n, what in (
                (len(self.doc.tileset.candidates), "candidates"),
                (len(self.doc.wang.tiles), "Wang tiles"),
            )
            if n
        ]
        if made:
            text += (
                f" The {' and the '.join(made)} made before lack it: generate them again "
                "(a project saved until then leaves them out)."
            )
        self._say("warning" if made else "info", text)

    def target_dialog(self, *_args) -> None:
        path = self.ask_open_path("Load transfer target", IMAGE_FILTER, "last_open_dir")
        if path:
            self.load_target(path)

    def load_target(self, path: str) -> None:
        """Load the texture-transfer target in the background."""
        self._read("open_target", read_image, path, self._on_target_loaded)

    def _on_target_loaded(self, path: str, loaded) -> None:
        self.doc.quilting.set_target(loaded.pixels)
        h, w = loaded.pixels.shape[:2]
        self._say(
            "info",
            f"Transfer target {Path(path).name} ({w}×{h}) loaded. Texture "
            "transfer (Ctrl+Shift+Return) re-creates it with the source.",
        )

    # ------------------------------------------------------------------ saving
    def save(self, *_args, wait: bool = False) -> bool:
        if not self.doc.project_path:
            return self.save_as(wait=wait)
        return self.save_to(self.doc.project_path, wait=wait)

    def save_as(self, *_args, wait: bool = False) -> bool:
        if not self.doc.has_source:
            self._say("warning", "Nothing to save: open an image first.")
            return False
        path = self.ask_save_path()
        return bool(path) and self.save_to(path, wait=wait)

    def save_to(self, path: str, *, wait: bool = False) -> bool:
        """Save the project to ``path``; ``wait`` saves in this thread (closing)."""
        try:
            project = project_io.to_project(self.doc)
        except ValueError as exc:
            self._say("error", str(exc))
            return False
        if wait:
            try:
                save_project(path, project)
            except (ProjectError, OSError) as exc:
                self._on_save_error(path, exc)
                return False
            self._on_saved(path, None)
            return True
        self.jobs.start(
            "save",
            save_project,
            path,
            project,
            label=f"Saving {Path(path).name}",
            pass_cancel=False,
            on_done=partial(self._on_saved, path),
            on_error=partial(self._on_save_error, path),
        )
        return True

    def _on_saved(self, path: str, _result) -> None:
        old_recovery = self.recovery_file()
        self.doc.mark_saved(path)
        for f in {old_recovery, self.recovery_file()}:
            f.unlink(missing_ok=True)
        self._remember(path, "last_project_dir", True)
        self._say("info", f"Saved {Path(path).name}.")

    def _on_save_error(self, path: str, exc) -> None:
        self._say("error", f"The project was not saved. {error_text(exc)}")

    # ------------------------------------------------------------------ images out
    def save_output(self, *_args, path: str | None = None) -> jobs.Job | None:
        """File ▸ Save output: the finished quilting / transfer output as an image at the
        source's bit depth (8 bits where the format has no 16)."""
        out = self.doc.quilting.finished_output
        if out is None:
            self._say("warning", "Nothing to save yet: synthesize a texture first.")
            return None
        path = path or self.ask_image_path("Save output", f"{self.doc.name}_quilted.png")
        if not path:
            return None
        return self._write_image("save_output", save_image, path, out, self._on_output_saved)

    def _on_output_saved(self, path: str, _result) -> None:
        self.doc.quilting.unsaved = False
        h, w = self.doc.quilting.output.shape[:2]
        self._say(
            "info",
            f"Saved the {w}×{h} output to {Path(path).name}.{self.doc.quilting.colour_only()}",
        )

    def export_seamless(self, *_args, path: str | None = None) -> jobs.Job | None:
        """File ▸ Export seamless tile: the tile alone, one file per material map."""
        maps = project_io.template_maps(self.doc)
        if maps is None:
            self._say(
                "warning", "No seamless tile yet: choose a tile size or draw the tile rectangle."
            )
            return None
        path = path or self.ask_image_path("Export seamless tile", f"{self.doc.name}_tile.png")
        if not path:
            return None
        return self._write_image("export_seamless", _export_seamless, path, maps, self._on_tile)

    def _on_tile(self, path: str, written) -> None:
        h, w = next(iter(project_io.template_maps(self.doc).values())).shape[:2]
        names = ", ".join(p.name for p in written)
        self._say("info", f"Exported the {w}×{h} seamless tile: {names}.")

    def _write_image(self, key: str, writer, path: str, image, on_done) -> jobs.Job:
        """``writer(path, image, bit_depth=)`` in the background; errors become messages."""
        depth = self.doc.source.bit_depth if Path(path).suffix.lower() in HIGH_DEPTH else 8
        source_depth = self.doc.source.bit_depth

        def done(result) -> None:
            settings.set("last_export_dir", str(Path(path).parent))
            on_done(path, result)

        return self.jobs.start(
            key,
            writer,
            path,
            image,
            bit_depth=depth,
            source_bit_depth=source_depth,
            label=f"Writing {Path(path).name}",
            pass_cancel=False,
            on_done=done,
            on_error=partial(self._on_write_error, path),
        )

    def _on_write_error(self, path: str, exc) -> None:
        self._say("error", f"{Path(path).name} was not written. {error_text(exc)}")

    # ------------------------------------------------------------------ autosave, recovery
    def recovery_file(self) -> Path:
        """Where autosave writes: next to the project, or in the settings folder if untitled."""
        if self.doc.project_path:
            return recovery_path(self.doc.project_path)
        return recovery_dir() / f"untitled.recovery{PROJECT_SUFFIX}"

    @Slot()
    def autosave_now(self) -> jobs.Job | None:
        """Write the recovery file in the background if there are unsaved changes."""
        if not self.doc.modified or not self.doc.has_source or self.closing:
            return None
        try:
            project = project_io.to_project(self.doc)
        except ValueError:
            return None
        target = self.recovery_file()
        target.parent.mkdir(parents=True, exist_ok=True)
        return self.jobs.start(
            "autosave",
            save_project,
            target,
            project,
            label="Autosaving",
            pass_cancel=False,
            on_error=self._on_autosave_error,
        )

    def _on_autosave_error(self, exc) -> None:
        self._say("warning", f"Autosave failed: {error_text(exc)}")

    def offer_recovery(self, path: Path) -> None:
        """Offer to reopen an autosaved recovery file (non-blocking banner)."""
        self._say(
            "warning",
            f"Quilt Studio did not close normally: unsaved work was recovered ({path.name}). "
            "Restore it?",
            (
                ("Restore", partial(self.restore_recovery, path)),
                ("Discard", partial(self._discard_recovery, path)),
            ),
        )

    def restore_recovery(self, path: Path, *_args) -> None:
        try:
            project = load_project(path)
        except ProjectError as exc:
            self._say("error", f"The recovery file cannot be read: {exc}")
            return
        saved_path = None
        if path.name.startswith(".") and ".recovery" in path.name:
            stem = path.name[1:].split(".recovery")[0]
            candidate = path.with_name(stem + PROJECT_SUFFIX)
            saved_path = str(candidate) if candidate.is_file() else None
        project_io.apply_project(self.doc, project, saved_path)
        self.doc.mark_dirty()  # recovered work is unsaved until the user saves it
        self._say("info", "Recovered the unsaved work. Save it to keep it.")

    def _discard_recovery(self, path: Path, *_args) -> None:
        path.unlink(missing_ok=True)

    def stop_autosave(self) -> None:
        """The window closes (after :meth:`confirm_discard`): no autosave from now on."""
        self.closing = True
        self.autosave_timer.stop()

    def remove_recovery_file(self) -> None:
        """A normal close (after the jobs stopped): nothing to recover next time."""
        self.recovery_file().unlink(missing_ok=True)
