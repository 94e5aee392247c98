"""The main window: wires the document, the pipeline and the views; menus, shortcuts, status.

Nothing here blocks a test: messages go to the message bar and the status bar, and the
only questions (unsaved changes, file names) are methods tests can replace
(:meth:`MainWindow.ask_save_changes`, :meth:`MainWindow.ask_open_path` ...).
"""

from __future__ import annotations

import logging
import os
from functools import partial
from pathlib import Path

from PySide6.QtCore import QSettings, Qt, QTimer, Slot
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import (
    QApplication,
    QDockWidget,
    QFileDialog,
    QLabel,
    QMainWindow,
    QMessageBox,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

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
from quilt_gui import jobs, params, settings
from quilt_gui.app import APP_NAME, apply_theme
from quilt_gui.document import Document, Source, safe_name
from quilt_gui.imaging import pixel_text, prepare_display
from quilt_gui.pipeline import Pipeline, error_text
from quilt_gui.widgets.candidate_dialog import CandidateDialog
from quilt_gui.widgets.canvas import ImageCanvas
from quilt_gui.widgets.gallery import CandidateView
from quilt_gui.widgets.overlap_panel import OverlapPanel
from quilt_gui.widgets.params_panel import QUILT_GROUPS, TILESET_GROUPS, ParamsPanel
from quilt_gui.widgets.preview import PreviewView
from quilt_gui.widgets.quilt_view import QuiltView
from quilt_gui.widgets.source_view import SourceView
from quilt_gui.widgets.status import JobStatus, MessageBar
from quilt_gui.widgets.tile_view import REPEATS, TileView
from resources import SAMPLE_NAMES, sample_path

log = logging.getLogger(__name__)

IMAGE_FILTER = "Images (" + " ".join(f"*{s}" for s in READ_SUFFIXES) + ")"
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


_warmup_started = False


def _warmup() -> None:
    import engine.seams

    engine.seams.warmup()


def start_warmup(manager: jobs.JobManager) -> jobs.Job | None:
    """Load (or compile) the numba seam kernels in a worker, once per process, so the first
    seam a person asks for is not held up by it and the GUI thread never is."""
    global _warmup_started
    if _warmup_started:
        return None
    _warmup_started = True
    return manager.start(
        "warmup",
        _warmup,
        label="Loading the seam kernels",
        pass_cancel=False,
        on_error=lambda exc: log.warning("seam kernel warm-up failed: %s", exc),
    )


def recovery_dir() -> Path:
    """Folder of the untitled-project recovery file (next to the settings file)."""
    return Path(QSettings().fileName()).parent / "recovery"


class MainWindow(QMainWindow):
    """Quilt Studio's editor window."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("MainWindow")
        self.setAcceptDrops(True)
        self.doc = Document(self)
        self.doc.params = params.coerce_all(settings.get("parameters"))  # the last used options
        self.jobs = jobs.manager()
        self.pipeline = Pipeline(self.doc, self.jobs, self)
        self.messages: list[tuple[str, str]] = []  # (level, text) log, newest last
        self._dialogs: dict[int, CandidateDialog] = {}
        self._closing = False
        self._criteria: dict[str, float] = {}
        self._make_actions()
        self._make_views()
        self._make_menus()
        self._make_status_bar()
        self._connect()
        self.autosave_timer = QTimer(self)
        self.autosave_timer.setInterval(max(5, settings.get("autosave_seconds")) * 1000)
        self.autosave_timer.timeout.connect(self.autosave_now)
        self.autosave_timer.start()
        start_warmup(self.jobs)
        self.resize(1500, 950)
        geo, state = settings.get("window_geometry"), settings.get("window_state")
        if not geo.isEmpty():
            self.restoreGeometry(geo)
        if not state.isEmpty():
            self.restoreState(state)
        self._update_title()
        self._update_actions()

    # ------------------------------------------------------------------ construction
    def _action(
        self, text: str, slot, shortcut=None, tip: str = "", *, checkable=False, checked=False
    ) -> QAction:
        a = QAction(text, self)
        if shortcut is not None:
            a.setShortcut(QKeySequence(shortcut))
            a.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        if tip:
            a.setToolTip(tip + (f" ({a.shortcut().toString()})" if shortcut else ""))
            a.setStatusTip(tip)
        if checkable:
            a.setCheckable(True)
            a.setChecked(checked)
        if slot is not None:  # None: the view that uses the action connects it
            (a.toggled if checkable else a.triggered).connect(slot)
        self.addAction(a)
        return a

    def _make_actions(self) -> None:
        A = self._action
        K = QKeySequence.StandardKey
        self.act_open = A(
            "&Open image or project…",
            self.open_dialog,
            K.Open,
            "Open a texture image or a .quiltproj project",
        )
        self.act_attach = A(
            "Attach &material map…",
            self.attach_dialog,
            None,
            "Add a normal / roughness / height ... map of the same size; it follows every cut",
        )
        self.act_save = A("&Save project", self.save, K.Save, "Save the project")
        self.act_save_as = A(
            "Save project &as…", self.save_as, K.SaveAs, "Save the project under a new name"
        )
        self.act_export = A(
            "&Export tile set…",
            self.export_dialog,
            "Ctrl+E",
            "Write the picked tiles, atlases, manifest, Tiled and Godot files",
        )
        self.act_quit = A("&Quit", self.close, K.Quit, "Close Quilt Studio")
        self.act_undo = self.doc.undo_stack.createUndoAction(self, "&Undo")
        self.act_undo.setShortcut(QKeySequence(K.Undo))
        self.act_redo = self.doc.undo_stack.createRedoAction(self, "&Redo")
        self.act_redo.setShortcut(QKeySequence(K.Redo))
        self.addActions([self.act_undo, self.act_redo])
        self.act_fit = A("&Fit in window", self._zoom_fit, "Ctrl+0", "Show the whole image")
        self.act_100 = A(
            "&Actual size (100 %)", self._zoom_100, "Ctrl+1", "One image pixel per screen pixel"
        )
        self.act_zoom_in = A("Zoom &in", self._zoom_in, K.ZoomIn, "Zoom in")
        self.act_zoom_out = A("Zoom &out", self._zoom_out, K.ZoomOut, "Zoom out")
        self.act_heat = A(
            "&Heat overlay of the error maps",
            self._set_heat,
            "H",
            "Show each overlap's error map over the source",
            checkable=True,
            checked=settings.get("heat_overlay"),
        )
        self.act_preview_grid = A(
            "Preview &grid overlay",
            None,
            "G",
            "Draw the tile borders over the preview",
            checkable=True,
            checked=settings.get("preview_grid"),
        )
        self.act_find = A(
            "&Find best tile",
            self.pipeline.find_template,
            "Ctrl+T",
            "Search the tile rectangle whose opposite borders match best",
        )
        self.act_generate = A(
            "&Generate candidates",
            self.pipeline.generate_candidates,
            "Ctrl+G",
            "Make the candidate tiles (locked ones are kept)",
        )
        self.act_reroll_layout = A(
            "Re-roll &layout",
            self.pipeline.reroll_layout,
            "Ctrl+R",
            "A new random arrangement of the picked tiles",
        )
        self.act_quilt = A(
            "&Synthesize",
            self.run_quilt,
            "Ctrl+Return",
            "Quilt the source into a texture of the output size (Quilting tab)",
        )
        self.act_load_target = A(
            "Load transfer &target…",
            self.target_dialog,
            None,
            "Open the image whose layout texture transfer imitates",
        )
        self.act_transfer = A(
            "Texture &transfer",
            self.run_transfer,
            "Ctrl+Shift+Return",
            "Re-create the target image with the source's texture",
        )
        self.act_clear_painted = A(
            "Clear painted e&xclusion",
            self._clear_painted,
            None,
            "Forget the source pixels painted as never to use",
        )
        self.act_repeats = {
            n: A(
                f"Seamless tile {n}×{n}",
                partial(self._set_repeats, n),
                str(n),
                f"Show the seamless tile repeated {n}×{n}",
                checkable=True,
            )
            for n in REPEATS
        }
        group = QActionGroup(self)
        for a in self.act_repeats.values():
            group.addAction(a)
        self.act_cancel = A(
            "&Cancel running job", self.jobs.stop_all, "Esc", "Stop the running computation"
        )
        self.act_clear_wp = A(
            "Clear &waypoints",
            self.doc.clear_waypoints,
            None,
            "Remove every waypoint of the template seams",
        )

    def _make_views(self) -> None:
        doc = self.doc
        self.source_view = SourceView(doc, self.pipeline)
        self.preview_view = PreviewView(doc, self.act_reroll_layout, self.act_preview_grid)
        self.tabs = QTabWidget()
        self.tabs.setDocumentMode(True)
        self.tabs.addTab(self.source_view, "Source")
        self.tabs.addTab(self.preview_view, "Preview")
        self.quilt_view = QuiltView(doc, (self.act_quilt, self.act_load_target, self.act_transfer))
        self.tabs.addTab(self.quilt_view, "Quilting")
        self.message_bar = MessageBar()
        central = QWidget()
        lay = QVBoxLayout(central)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(0)
        lay.addWidget(self.message_bar)
        lay.addWidget(self.tabs, 1)
        self.setCentralWidget(central)
        self.params_panel = ParamsPanel(
            doc,
            {
                "Template": [self.act_find],
                "Candidates": [self.act_generate],
                "Preview": [self.act_reroll_layout],
                "Quilting": [self.act_quilt],
                "Transfer": [self.act_load_target, self.act_transfer],
                "Exclusion": [self.act_clear_painted],
            },
        )
        self.params_panel.show_groups(TILESET_GROUPS)
        self.overlap_panel = OverlapPanel(doc, self.pipeline)
        self.tile_view = TileView(doc)
        for n, a in self.act_repeats.items():
            a.setChecked(n == self.tile_view.repeats)
            self.tile_view.repeat_buttons.button(n).setToolTip(a.toolTip())
        self.gallery = CandidateView(doc)
        self.docks = {}
        for key, title, widget, area in (
            ("params", "Parameters", self.params_panel, Qt.DockWidgetArea.LeftDockWidgetArea),
            (
                "overlaps",
                "Overlaps, error maps and seams",
                self.overlap_panel,
                Qt.DockWidgetArea.RightDockWidgetArea,
            ),
            ("tile", "Seamless tile", self.tile_view, Qt.DockWidgetArea.RightDockWidgetArea),
            ("gallery", "Candidates", self.gallery, Qt.DockWidgetArea.BottomDockWidgetArea),
        ):
            dock = QDockWidget(title, self)
            dock.setObjectName(f"dock_{key}")
            dock.setWidget(widget)
            self.addDockWidget(area, dock)
            self.docks[key] = dock
        # side docks run the full height; the gallery sits under the canvas only
        self.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        self.setCorner(Qt.Corner.BottomLeftCorner, Qt.DockWidgetArea.LeftDockWidgetArea)
        self.resizeDocks([self.docks["params"]], [300], Qt.Orientation.Horizontal)
        self.resizeDocks([self.docks["overlaps"]], [360], Qt.Orientation.Horizontal)
        self.resizeDocks([self.docks["gallery"]], [260], Qt.Orientation.Vertical)

    def _make_menus(self) -> None:
        mb = self.menuBar()
        m = mb.addMenu("&File")
        m.addAction(self.act_open)
        self.samples_menu = m.addMenu("Open &sample")
        for name in SAMPLE_NAMES:
            a = self.samples_menu.addAction(name.capitalize())
            a.triggered.connect(partial(self._open_sample, name))
        self.recent_menu = m.addMenu("Open &recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent_menu)
        m.addAction(self.act_attach)
        m.addSeparator()
        m.addActions([self.act_save, self.act_save_as, self.act_export])
        m.addSeparator()
        m.addAction(self.act_quit)
        m = mb.addMenu("&Edit")
        m.addActions([self.act_undo, self.act_redo])
        m.addSeparator()
        m.addAction(self.act_clear_wp)
        m.addAction(self.act_clear_painted)
        m = mb.addMenu("&View")
        m.addActions([self.act_fit, self.act_100, self.act_zoom_in, self.act_zoom_out])
        m.addSeparator()
        m.addActions([self.act_heat, self.act_preview_grid])
        m.addSeparator()
        m.addActions(list(self.act_repeats.values()))
        m.addSeparator()
        for dock in self.docks.values():
            m.addAction(dock.toggleViewAction())
        theme = m.addMenu("&Theme")
        group = QActionGroup(self)
        for name in ("dark", "light"):
            a = theme.addAction(name.capitalize())
            a.setCheckable(True)
            a.setChecked(settings.get("theme") == name)
            a.triggered.connect(partial(self.set_theme, name))
            group.addAction(a)
        m = mb.addMenu("&Tile set")
        m.addActions([self.act_find, self.act_generate, self.act_reroll_layout])
        m.addSeparator()
        m.addAction(self.act_cancel)
        m = mb.addMenu("&Quilting")
        m.addActions([self.act_quilt, self.act_load_target, self.act_transfer])
        m = mb.addMenu("&Help")
        m.addAction("&Keyboard and mouse", self.show_help)

    def _make_status_bar(self) -> None:
        sb = self.statusBar()
        self.pixel_label = QLabel()
        self.pixel_label.setMinimumWidth(260)
        self.pixel_label.setToolTip("Pixel under the cursor: x, y and value")
        self.criterion_label = QLabel()
        self.criterion_label.setToolTip(
            "Seam criterion (sum of the error along the seam) of "
            "the left/right (H) and top/bottom (V) overlaps"
        )
        self.job_status = JobStatus(self.jobs)
        sb.addPermanentWidget(self.pixel_label)
        sb.addPermanentWidget(self.criterion_label)
        sb.addPermanentWidget(self.job_status)

    def _connect(self) -> None:
        doc = self.doc
        self.pipeline.message.connect(self.show_message)
        self.pipeline.seam_updated.connect(self._on_seam_updated)
        doc.modified_changed.connect(self._update_title)
        doc.path_changed.connect(self._update_title)
        doc.source_changed.connect(self._update_title)
        doc.source_changed.connect(self._update_actions)
        doc.seamless_changed.connect(self._on_seamless_changed)
        doc.candidates_reset.connect(self._update_actions)
        doc.candidate_inserted.connect(self._update_actions)
        doc.picks_changed.connect(self._update_actions)
        self.gallery.open_requested.connect(self.open_candidate)
        self.gallery.reroll_requested.connect(self.reroll_candidate)
        self.gallery.current_changed.connect(self._on_gallery_current)
        self.source_view.patch_moved.connect(self._on_patch_moved)
        self.tabs.currentChanged.connect(self._on_tab_changed)
        self.quilt_view.selection_changed.connect(self._show_criteria)
        self.tile_view.repeats_changed.connect(self._on_repeats_changed)
        for canvas in self.canvases():
            canvas.hovered.connect(partial(self._on_hover, canvas))
        self.source_view.set_heat_visible(self.act_heat.isChecked())

    def canvases(self) -> list[ImageCanvas]:
        return [
            self.source_view,
            self.preview_view.canvas,
            self.tile_view.canvas,
            *self.overlap_panel.views.values(),
            self.quilt_view.sample,
            self.quilt_view.target,
            self.quilt_view.output,
            self.quilt_view.inspector,
        ]

    # ------------------------------------------------------------------ messages
    @Slot(str, str)
    def show_message(self, level: str, text: str, actions=()) -> None:
        """Tell the user something without blocking (banner + status bar + log)."""
        self.messages.append((level, text))
        getattr(log, {"error": "error", "warning": "warning"}.get(level, "info"))(text)
        if actions or level != "info" or not self.message_bar.waiting_for_answer():
            self.message_bar.show_message(level, text, actions)
        self.statusBar().showMessage(text, 10_000)

    def last_message(self, level: str | None = None) -> str:
        for lv, text in reversed(self.messages):
            if level is None or lv == level:
                return text
        return ""

    # ------------------------------------------------------------------ questions (patchable)
    def ask_save_changes(self) -> str:
        """ "save", "discard" or "cancel" for unsaved changes (tests replace this)."""
        box = QMessageBox(
            QMessageBox.Icon.Warning,
            APP_NAME,
            f"Save the changes to “{self.doc.name}” before closing?",
            QMessageBox.StandardButton.Save
            | QMessageBox.StandardButton.Discard
            | QMessageBox.StandardButton.Cancel,
            self,
        )
        box.setDefaultButton(QMessageBox.StandardButton.Save)
        answer = box.exec()
        return {
            QMessageBox.StandardButton.Save: "save",
            QMessageBox.StandardButton.Discard: "discard",
        }.get(QMessageBox.StandardButton(answer), "cancel")

    def ask_open_path(self, caption: str, filters: str, key: str) -> str:
        path, _ = QFileDialog.getOpenFileName(self, caption, settings.get(key), filters)
        return path

    def ask_save_path(self) -> str:
        start = self.doc.project_path or os.path.join(
            settings.get("last_project_dir"), self.doc.name + PROJECT_SUFFIX
        )
        path, _ = QFileDialog.getSaveFileName(self, "Save project", start, PROJECT_FILTER)
        if path and not path.endswith(PROJECT_SUFFIX):
            path += PROJECT_SUFFIX
        return path

    def _confirm_discard(self) -> bool:
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

    def _open_sample(self, name: str, *_checked) -> None:
        self.open_path(str(sample_path(name)), remember=False)

    def open_path(self, path: str, *, confirm: bool = True, remember: bool = True) -> None:
        """Open an image or a ``.quiltproj`` in the background (errors become messages)."""
        path = os.fspath(path)
        if confirm and not self._confirm_discard():
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
        self._remember(path, "last_open_dir", remember)
        h, w = loaded.pixels.shape[:2]
        self.show_message(
            "info",
            f"Opened {Path(path).name}: {w}×{h}, {loaded.bit_depth}-bit "
            f"{mode_text(loaded.mode)}. Next: Find best tile (Ctrl+T) or draw the "
            "tile rectangle.",
        )
        self.tabs.setCurrentWidget(self.source_view)

    def _on_project_loaded(self, path: str, project) -> None:
        self.doc.from_project(project, path)
        self._remember(path, "last_project_dir", True)
        self.show_message("info", f"Opened project {Path(path).name}.")
        rec = newer_recovery(path)
        if rec is not None:
            self.offer_recovery(rec)

    def _on_open_error(self, path: str, exc) -> None:
        if isinstance(exc, (ImageError, ProjectError)):
            text = error_text(exc)
        else:
            text = f"{path}: cannot be opened ({error_text(exc)})"
        self.show_message("error", f"Could not open the file. {text}")

    def _remember(self, path: str, dir_key: str, recent: bool) -> None:
        settings.set(dir_key, str(Path(path).parent))
        if recent:
            settings.add_recent_file(str(Path(path).resolve()))

    @Slot()
    def _fill_recent_menu(self) -> None:
        self.recent_menu.clear()
        files = settings.get("recent_files")
        if not files:
            a = self.recent_menu.addAction("(none)")
            a.setEnabled(False)
            return
        for i, f in enumerate(files):
            a = self.recent_menu.addAction(f"&{(i + 1) % 10} {Path(f).name}")
            a.setToolTip(f)
            a.setStatusTip(f)
            a.triggered.connect(partial(self._open_recent, f))
        self.recent_menu.addSeparator()
        self.recent_menu.addAction("Clear list", self._clear_recent)

    @Slot()
    def _clear_recent(self) -> None:
        settings.set("recent_files", [])

    def _open_recent(self, path: str, *_checked) -> None:
        if not Path(path).exists():
            settings.remove_recent_file(path)
            self.show_message("error", f"{path} no longer exists; removed from the recent files.")
            return
        self.open_path(path)

    def attach_dialog(self) -> None:
        path = self.ask_open_path("Attach material map", IMAGE_FILTER, "last_open_dir")
        if path:
            self.attach_map(path)

    def attach_map(self, path: str) -> None:
        """Load ``path`` as a material map of the source (kind guessed from its name)."""
        if not self.doc.has_source:
            self.show_message("warning", "Open a source image before attaching material maps.")
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
            self.show_message("error", str(exc))
            return
        self.show_message(
            "info",
            f"Attached {Path(path).name} as the “{name}” map ({kind}); it follows every cut.",
        )

    # ------------------------------------------------------------------ drag and drop
    def dragEnterEvent(self, event) -> None:  # noqa: N802 - Qt API
        if any(u.isLocalFile() for u in event.mimeData().urls()):
            event.acceptProposedAction()

    def dropEvent(self, event) -> None:  # noqa: N802 - Qt API
        files = [u.toLocalFile() for u in event.mimeData().urls() if u.isLocalFile()]
        if files:
            event.acceptProposedAction()
            self.open_path(files[0])

    # ------------------------------------------------------------------ saving
    def save(self, *_args, wait: bool = False) -> bool:
        if not self.doc.project_path:
            return self.save_as(wait=wait)
        return self.save_to(self.doc.project_path, wait=wait)

    def save_as(self, *_args, wait: bool = False) -> bool:
        if not self.doc.has_source:
            self.show_message("warning", "Nothing to save: open an image first.")
            return False
        path = self.ask_save_path()
        return bool(path) and self.save_to(path, wait=wait)

    def save_to(self, path: str, *, wait: bool = False) -> bool:
        """Save the project to ``path``; ``wait`` saves in this thread (closing)."""
        try:
            project = self.doc.to_project()
        except ValueError as exc:
            self.show_message("error", str(exc))
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
        self.show_message("info", f"Saved {Path(path).name}.")

    def _on_save_error(self, path: str, exc) -> None:
        self.show_message("error", f"The project was not saved. {error_text(exc)}")

    def recovery_file(self) -> Path:
        """Where autosave writes: next to the project, or in the settings folder if untitled."""
        if self.doc.project_path:
            return recovery_path(self.doc.project_path)
        return recovery_dir() / f"untitled.recovery{PROJECT_SUFFIX}"

    @Slot()
    def autosave_now(self) -> jobs.Job | None:
        """Write the recovery file in the background if there are unsaved changes."""
        if not self.doc.modified or not self.doc.has_source or self._closing:
            return None
        try:
            project = self.doc.to_project()
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
        self.show_message("warning", f"Autosave failed: {error_text(exc)}")

    def offer_recovery(self, path: Path) -> None:
        """Offer to reopen an autosaved recovery file (non-blocking banner)."""
        self.show_message(
            "warning",
            f"Quilt Studio did not close normally: unsaved work was recovered ({path.name}). "
            "Restore it?",
            actions=(
                ("Restore", partial(self.restore_recovery, path)),
                ("Discard", partial(self._discard_recovery, path)),
            ),
        )

    def restore_recovery(self, path: Path, *_args) -> None:
        try:
            project = load_project(path)
        except ProjectError as exc:
            self.show_message("error", f"The recovery file cannot be read: {exc}")
            return
        saved_path = None
        if path.name.startswith(".") and ".recovery" in path.name:
            stem = path.name[1:].split(".recovery")[0]
            candidate = path.with_name(stem + PROJECT_SUFFIX)
            saved_path = str(candidate) if candidate.is_file() else None
        self.doc.from_project(project, saved_path)
        self.doc.mark_dirty()  # recovered work is unsaved until the user saves it
        self.show_message("info", "Recovered the unsaved work. Save it to keep it.")

    def _discard_recovery(self, path: Path, *_args) -> None:
        path.unlink(missing_ok=True)

    # ------------------------------------------------------------------ export
    def export_dialog(self) -> None:
        from quilt_gui.widgets.export_dialog import ExportDialog

        if not self.doc.candidates:
            self.show_message(
                "warning", "Nothing to export yet: generate candidates and pick the tiles to keep."
            )
            return
        dlg = getattr(self, "_export_dialog", None)
        if dlg is None:
            dlg = ExportDialog(self.doc, self.jobs, self)
            dlg.message.connect(self.show_message)
            self._export_dialog = dlg
        dlg.refresh()
        dlg.show()
        dlg.raise_()

    # ------------------------------------------------------------------ candidates
    @Slot(int)
    def open_candidate(self, index: int) -> CandidateDialog:
        dlg = self._dialogs.get(index)
        if dlg is None:
            dlg = CandidateDialog(self.doc, index, self)
            dlg.reroll_requested.connect(self.reroll_candidate)
            self._dialogs[index] = dlg
        dlg.set_index(index)
        dlg.show()
        dlg.raise_()
        self.source_view.show_patch(index)
        return dlg

    @Slot(int)
    def reroll_candidate(self, index: int) -> None:
        if self.doc.candidates[index].locked:
            self.show_message("warning", f"Candidate #{index + 1} is locked; unlock it to re-roll.")
            return
        self.pipeline.remake_candidate(index)

    @Slot(int)
    def _on_gallery_current(self, row: int) -> None:
        self.source_view.show_patch(row if row >= 0 else None)

    @Slot(int, object)
    def _on_patch_moved(self, index: int, origin) -> None:
        self.pipeline.remake_candidate(index, origin=origin)

    # ------------------------------------------------------------------ quilting
    def run_quilt(self, *_args) -> None:
        self.tabs.setCurrentWidget(self.quilt_view)
        self.pipeline.run_quilt()

    def _clear_painted(self, *_args) -> None:
        self.source_view.painter.clear_painted()

    def run_transfer(self, *_args) -> None:
        self.tabs.setCurrentWidget(self.quilt_view)
        self.pipeline.run_transfer()

    def target_dialog(self, *_args) -> None:
        path = self.ask_open_path("Load transfer target", IMAGE_FILTER, "last_open_dir")
        if path:
            self.load_target(path)

    def load_target(self, path: str) -> None:
        """Load the texture-transfer target in the background."""
        self._read("open_target", read_image, path, self._on_target_loaded)

    def _on_target_loaded(self, path: str, loaded) -> None:
        self.doc.set_transfer_target(loaded.pixels)
        h, w = loaded.pixels.shape[:2]
        self.show_message(
            "info",
            f"Transfer target {Path(path).name} ({w}×{h}) loaded. Texture "
            "transfer (Ctrl+Shift+Return) re-creates it with the source.",
        )

    @Slot(int)
    def _on_tab_changed(self, _index: int) -> None:
        quilting = self.tabs.currentWidget() is self.quilt_view
        self.params_panel.show_groups(QUILT_GROUPS if quilting else TILESET_GROUPS)
        for key in ("overlaps", "tile", "gallery"):
            self.docks[key].setVisible(not quilting)
        self._show_criteria()

    # ------------------------------------------------------------------ view actions
    def current_canvas(self) -> ImageCanvas:
        w = QApplication.focusWidget()
        while w is not None and not isinstance(w, ImageCanvas):
            w = w.parentWidget()
        if isinstance(w, ImageCanvas):
            return w
        current = self.tabs.currentWidget()
        return current if isinstance(current, ImageCanvas) else current.canvas

    def _zoom_fit(self) -> None:
        self.current_canvas().fit()

    def _zoom_100(self) -> None:
        self.current_canvas().actual_size()

    def _zoom_in(self) -> None:
        self.current_canvas().zoom_in()

    def _zoom_out(self) -> None:
        self.current_canvas().zoom_out()

    def _set_repeats(self, n: int, *_checked) -> None:
        self.tile_view.set_repeats(n)

    @Slot(int)
    def _on_repeats_changed(self, n: int) -> None:
        self.act_repeats[n].setChecked(True)

    def _set_heat(self, on: bool) -> None:
        settings.set("heat_overlay", bool(on))
        self.source_view.set_heat_visible(on)

    def set_theme(self, name: str, *_checked) -> None:
        settings.set("theme", name)
        apply_theme(QApplication.instance(), name)

    def show_help(self) -> None:
        self.show_message(
            "info",
            (
                "Wheel: zoom about the cursor · drag: pan · Ctrl+0 fit · Ctrl+1 100 % · "
                "drag the yellow rectangle or its handles, arrow keys nudge (Shift: 10 px) · "
                "Ctrl+click an overlap (or click in the overlaps panel): waypoint, right-click "
                "removes · Shift+drag on the source paints pixels never to use, "
                "Shift+right-drag erases, Ctrl+Shift+click excludes a colour · "
                "H heat overlay · 1 / 3 / 5: seamless tile 1×1 / 3×3 / 5×5 · "
                "gallery: click picks, Shift+click picks a range, "
                "Space, Ctrl+A all, Enter or double-click opens, L locks, R re-rolls, "
                "right-click: preview weight · drag the orange patch rectangle to rebuild a "
                "candidate · Ctrl+R re-rolls the layout, G its grid · Esc cancels the running "
                "job."
            ),
        )

    # ------------------------------------------------------------------ status
    def _on_hover(self, canvas: ImageCanvas, px) -> None:
        a = canvas.array
        if px is None or a is None:
            self.pixel_label.setText("")
            return
        r, c = px
        depth = self.doc.source.bit_depth if canvas is self.source_view and self.doc.source else 8
        self.pixel_label.setText(f"x {c}, y {r} = ({pixel_text(a, r, c, depth)})")

    @Slot(object)
    def _on_seam_updated(self, update) -> None:
        self._criteria[update.which] = float(update.seam.criterion)
        self._show_criteria()

    @Slot()
    def _on_seamless_changed(self) -> None:
        s = self.doc.seamless
        self._criteria = {} if s is None else dict(s.criterion)
        self._show_criteria()
        self._update_actions()

    @Slot()
    def _show_criteria(self) -> None:
        """The seam criterion of what is in front: the template's seams, or the inspected
        quilting block's cut in the Quilting tab."""
        if self.tabs.currentWidget() is self.quilt_view:
            rec = self.quilt_view.selected_block()
            has_cut = rec is not None and len(rec.path)
            text = f"block #{rec.index + 1} seam {rec.criterion:.3f}" if has_cut else ""
            self.criterion_label.setText(text)
            return
        parts = [f"{k[0].upper()} {v:.3f}" for k, v in sorted(self._criteria.items())]
        self.criterion_label.setText("seam " + " · ".join(parts) if parts else "")

    @Slot()
    def _update_title(self, *_args) -> None:
        name = Path(self.doc.project_path).name if self.doc.project_path else self.doc.name
        self.setWindowTitle(f"{name}[*] — {APP_NAME}")
        self.setWindowModified(self.doc.modified)

    @Slot()
    def _update_actions(self, *_args) -> None:
        has = self.doc.has_source
        for a in (
            self.act_find,
            self.act_save,
            self.act_save_as,
            self.act_attach,
            self.act_quilt,
            self.act_load_target,
            self.act_transfer,
        ):
            a.setEnabled(has)
        self.act_generate.setEnabled(has and self.doc.seamless is not None)
        self.act_export.setEnabled(bool(self.doc.candidates))
        self.act_reroll_layout.setEnabled(bool(self.doc.picks))
        n = len(self.doc.candidates)
        title = f"Candidates — {len(self.doc.picks)} of {n} picked" if n else "Candidates"
        if self.doc.candidates_outdated:
            title += " — made from an earlier template (Generate to update)"
        self.docks["gallery"].setWindowTitle(title)

    # ------------------------------------------------------------------ closing
    def closeEvent(self, event) -> None:  # noqa: N802 - Qt API
        if not self._confirm_discard():
            event.ignore()
            return
        self._closing = True
        self.autosave_timer.stop()
        self.pipeline.shutdown()
        self.jobs.shutdown(3000)
        self.recovery_file().unlink(missing_ok=True)
        settings.set("window_geometry", self.saveGeometry())
        settings.set("window_state", self.saveState())
        settings.set("parameters", self.doc.params)
        for dlg in self._dialogs.values():
            dlg.close()
        event.accept()
        super().closeEvent(event)
