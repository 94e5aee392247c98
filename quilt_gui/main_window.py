"""The main window: wires the document, the pipeline and the views; menus, shortcuts, status.

Nothing here blocks a test: messages go to the message bar and the status bar. Opening,
saving, autosave and recovery are :attr:`MainWindow.files` (:mod:`quilt_gui.files`), whose
questions (unsaved changes, file names) are methods tests can replace.
"""

from __future__ import annotations

import logging
from functools import partial
from pathlib import Path

from PySide6.QtCore import Qt, Slot
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import (
    QApplication,
    QDialog,
    QDockWidget,
    QLabel,
    QMainWindow,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from quilt_gui import jobs, params, settings, window_geometry
from quilt_gui.document import Document
from quilt_gui.files import ProjectFiles
from quilt_gui.heal_tool import HealTool
from quilt_gui.pipeline import Pipeline
from quilt_gui.theme import apply_theme
from quilt_gui.wang_runner import WangRunner
from quilt_gui.widgets.candidate_dialog import CandidateDialog
from quilt_gui.widgets.canvas import ImageCanvas
from quilt_gui.widgets.flatten_compare import FlattenCompare
from quilt_gui.widgets.gallery import CandidateView
from quilt_gui.widgets.help import GettingStarted, ShortcutSheet
from quilt_gui.widgets.library import LibraryView
from quilt_gui.widgets.overlap_panel import OverlapPanel
from quilt_gui.widgets.params_panel import QUILT_GROUPS, TILESET_GROUPS, WANG_GROUPS, ParamsPanel
from quilt_gui.widgets.preview import PreviewView
from quilt_gui.widgets.quilt_view import QuiltView
from quilt_gui.widgets.source_view import SourceView
from quilt_gui.widgets.status import ElidingLabel, JobStatus, MessageBar
from quilt_gui.widgets.tile_view import REPEATS, TileView
from quilt_gui.widgets.wang_view import WangView
from quilt_gui.widgets.watch_search import describe_seam
from quilt_gui.widgets.wrap_view import WrapView
from resources import SAMPLE_NAMES

log = logging.getLogger(__name__)

_warmup_started = False


def _warmup() -> None:
    import engine.quilting.synthesis
    import engine.seams

    engine.seams.warmup()
    engine.quilting.synthesis.warmup()


def start_warmup(manager: jobs.JobManager) -> jobs.Job | None:
    """Load (or compile) the numba seam and quilting kernels in a worker, once per process, so
    the first seam or quilt a person asks for is not held up by it and the GUI thread never is."""
    global _warmup_started
    if _warmup_started:
        return None
    _warmup_started = True
    return manager.start(
        "warmup",
        _warmup,
        label="Loading the seam and quilting kernels",
        pass_cancel=False,
        on_error=lambda exc: log.warning("seam kernel warm-up failed: %s", exc),
    )


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
        self.wang_runner = WangRunner(self.doc, self.pipeline, self.jobs, self)
        self.files = ProjectFiles(self.doc, self.jobs, self)
        self.messages: list[tuple[str, str]] = []  # (level, text) log, newest last
        self._dialogs: dict[int, CandidateDialog] = {}
        self._help: dict[str, QDialog] = {}
        self._criteria: dict[str, float] = {}
        self._left_open: list[bool] | None = None  # tile set docks open, while a tab hides them
        self._make_actions()
        self._make_views()
        self._make_menus()
        self._make_status_bar()
        self._connect()
        start_warmup(self.jobs)
        window_geometry.place(self, settings.get("window_geometry"))
        state = settings.get("window_state")
        if not state.isEmpty():
            self.restoreState(state)  # saved as the Source tab has it (see closeEvent)
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
            self.files.open_dialog,
            K.Open,
            "Open a texture image or a .quiltproj project",
        )
        self.act_open_library = A(
            "Open &library…",
            self.open_library_dialog,
            "Ctrl+Shift+L",
            "Browse a library made by quilt-studio batch and curate its photos one by one",
        )
        self.act_attach = A(
            "Attach &material map…",
            self.files.attach_dialog,
            None,
            "Add a normal / roughness / height ... map of the same size; tile cuts carry it",
        )
        self.act_save = A("&Save project", self.files.save, K.Save, "Save the project")
        self.act_save_as = A(
            "Save project &as…", self.files.save_as, K.SaveAs, "Save the project under a new name"
        )
        self.act_export = A(
            "&Export tile set…",
            self.export_dialog,
            "Ctrl+E",
            "Write the picked tiles, atlases, manifest, Tiled and Godot files",
        )
        self.act_export_seamless = A(
            "Export seamless &tile…",
            self.files.export_seamless,
            "Ctrl+Shift+E",
            "Write the seamless tile alone, one file per material map",
        )
        self.act_save_output = A(
            "Save &output…",
            self.files.save_output,
            None,  # Ctrl+Shift+S while the Quilting tab is in front (see _on_tab_changed)
            "Save the synthesized texture as an image",
        )
        self.act_quit = A("&Quit", self.close, K.Quit, "Close Quilt Studio")
        self.act_undo = self.doc.undo_group.createUndoAction(self, "&Undo")
        self.act_undo.setShortcut(QKeySequence(K.Undo))
        self.act_redo = self.doc.undo_group.createRedoAction(self, "&Redo")
        # whatever the platform's keymap: Ctrl+Y (Windows style) and Ctrl+Shift+Z (macOS, KDE)
        redo = [QKeySequence(K.Redo), QKeySequence("Ctrl+Y"), QKeySequence("Ctrl+Shift+Z")]
        self.act_redo.setShortcuts(list({k.toString(): k for k in redo}.values()))
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
            self.files.target_dialog,
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
        self.act_heal_brush = A(
            "Heal &brush",
            None,
            "J",
            "Paint the region to heal on the source (drag; right-drag erases)",
            checkable=True,
        )
        self.act_heal = A(
            "&Heal painted region",
            None,
            "Ctrl+Shift+H",
            "Fill the painted region from the rest of the source (quilted, seams cut)",
        )
        self.act_clear_heal = A(
            "Clear region to heal", None, None, "Forget the region painted to heal"
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
            self.doc.tileset.clear_waypoints,
            None,
            "Remove every waypoint of the template seams",
        )

    def _make_views(self) -> None:
        doc = self.doc
        self.source_view = SourceView(doc, self.pipeline)
        self.flatten_compare = FlattenCompare(doc, self.pipeline, self.source_view, self)
        self.addAction(self.flatten_compare.action)  # its key F, and the shortcut sheet
        self.heal_tool = HealTool(doc, self.pipeline, self.source_view, self)
        self.act_heal_brush.toggled.connect(self.heal_tool.set_brush)
        self.act_heal.triggered.connect(self.heal_tool.run)
        self.act_clear_heal.triggered.connect(self.heal_tool.clear)
        self.preview_view = PreviewView(doc, self.act_reroll_layout, self.act_preview_grid)
        self.tabs = QTabWidget()
        self.tabs.setDocumentMode(True)
        self.tabs.addTab(self.source_view, "Source")
        self.tabs.addTab(self.preview_view, "Preview")
        self.wrap_view = WrapView(doc)
        self.tabs.addTab(self.wrap_view, "Wrap-around")
        self.tabs.setTabToolTip(
            2, "The seamless tile (or the preview) repeated without end, to pan across its edges"
        )
        self.wang_view = WangView(doc, self.wang_runner)
        self.tabs.addTab(self.wang_view, "Wang tiles")
        self.tabs.setTabToolTip(
            3, "A Wang tile set: tiles whose edges vary, any two with matching colours join"
        )
        self.quilt_view = QuiltView(doc, (self.act_quilt, self.act_load_target, self.act_transfer))
        self.quilt_view.set_output_actions((self.act_save_output, self.act_fit, self.act_100))
        self.tabs.addTab(self.quilt_view, "Quilting")
        central = QWidget()
        lay = QVBoxLayout(central)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.tabs, 1)
        self.message_bar = MessageBar(central)  # floats over the canvas, outside the layout
        self.message_bar.covered.connect(self.wang_view.keep_clear_of)  # but not the Wang tab's
        self.message_bar.dismissed.connect(self._clear_status_message)
        self.setCentralWidget(central)
        self.params_panel = ParamsPanel(
            doc,
            {
                "Tile": [self.act_find],
                "Candidates": [self.act_generate],
                "Preview": [self.act_reroll_layout],
                "Quilting": [self.act_quilt],
                "Transfer": [self.act_load_target, self.act_transfer],
                "Exclusion": [self.act_clear_painted],
                "Heal": [self.act_heal_brush, self.act_heal],
            },
        )
        self.params_panel.show_groups(TILESET_GROUPS)
        self.overlap_panel = OverlapPanel(doc, self.pipeline)
        self.tile_view = TileView(doc)
        for n, a in self.act_repeats.items():
            a.setChecked(n == self.tile_view.repeats)
            self.tile_view.repeat_buttons.button(n).setToolTip(a.toolTip())
        self.gallery = CandidateView(doc)
        self.library_view = LibraryView()
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
            ("library", "Library", self.library_view, Qt.DockWidgetArea.BottomDockWidgetArea),
        ):
            dock = QDockWidget(title, self)
            dock.setObjectName(f"dock_{key}")
            dock.setWidget(widget)
            self.addDockWidget(area, dock)
            self.docks[key] = dock
        self.tabifyDockWidget(self.docks["gallery"], self.docks["library"])
        self.docks["library"].hide()  # shown by File ▸ Open library…
        self.docks["gallery"].raise_()
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
            a.triggered.connect(partial(self.files.open_sample, name))
        self.recent_menu = m.addMenu("Open &recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent_menu)
        m.addAction(self.act_open_library)
        m.addAction(self.act_attach)
        m.addSeparator()
        m.addActions([self.act_save, self.act_save_as])
        m.addSeparator()
        m.addActions([self.act_export_seamless, self.act_export, self.act_save_output])
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
        m.addActions([self.act_heat, self.flatten_compare.action, self.act_preview_grid])
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
        m.addActions([self.act_heal_brush, self.act_heal, self.act_clear_heal])
        m.addSeparator()
        m.addAction(self.act_cancel)
        m = mb.addMenu("&Quilting")
        m.addActions([self.act_quilt, self.act_load_target, self.act_transfer])
        m = mb.addMenu("&Help")
        m.addAction("&Getting started", self.show_getting_started)
        m.addAction("&Keyboard and mouse", self.show_help)

    def _make_status_bar(self) -> None:
        sb = self.statusBar()
        self.pixel_label = QLabel()
        self.pixel_label.setMinimumWidth(260)
        self.pixel_label.setToolTip("Pixel under the cursor: x, y and value")
        self.criterion_label = ElidingLabel(  # the whole line, then this, in its tooltip
            "Seam criterion (sum of the error along the seam) of "
            "the left/right (H) and top/bottom (V) overlaps, and the method and variant "
            "that made the seams",
            least="seam H 0.000 · V 0.000",  # the figures go last
        )
        self.job_status = JobStatus(self.jobs)
        sb.addPermanentWidget(self.pixel_label)
        sb.addPermanentWidget(self.criterion_label)
        sb.addPermanentWidget(self.job_status)

    def _connect(self) -> None:
        doc = self.doc
        for said in (self.pipeline.message, self.wang_runner.message, self.wang_runner.advice):
            said.connect(self.show_message)
        self.wang_runner.retracted.connect(self.message_bar.retract)
        self.wang_view.export_requested.connect(partial(self.export_dialog, wang=True))
        self.heal_tool.message.connect(self.show_message)
        self.files.message.connect(self.show_message)
        self.files.image_opened.connect(self._on_image_opened)
        self.files.wang_opened.connect(lambda: self.tabs.setCurrentWidget(self.wang_view))
        self.pipeline.seam_updated.connect(self._on_seam_updated)
        self.overlap_panel.watch.state_changed.connect(self._show_criteria)
        doc.modified_changed.connect(self._update_title)
        doc.path_changed.connect(self._update_title)
        doc.source_changed.connect(self._update_title)
        doc.source_changed.connect(self._update_actions)
        doc.tileset.seamless_changed.connect(self._on_seamless_changed)
        doc.tileset.candidates_reset.connect(self._update_actions)
        doc.tileset.candidate_inserted.connect(self._update_actions)
        doc.tileset.picks_changed.connect(self._update_actions)
        for signal in (doc.quilting.reset, doc.quilting.finished, doc.quilting.restored):
            signal.connect(self._update_actions)
        doc.wang.reset.connect(self._update_actions)
        doc.wang.layout_changed.connect(self._update_actions)
        self.gallery.open_requested.connect(self.open_candidate)
        self.gallery.reroll_requested.connect(self.reroll_candidate)
        self.gallery.current_changed.connect(self._on_gallery_current)
        self.source_view.patch_moved.connect(self._on_patch_moved)
        self.tabs.currentChanged.connect(self._on_tab_changed)
        self.quilt_view.selection_changed.connect(self._show_criteria)
        self.tile_view.repeats_changed.connect(self._on_repeats_changed)
        self.params_panel.tile_size_edited.connect(self._on_tile_size_edited)
        self.tile_view.wrap_requested.connect(partial(self.tabs.setCurrentWidget, self.wrap_view))
        self.library_view.open_project.connect(lambda path: self.files.open_path(path))
        self.library_view.message.connect(self.show_message)
        for canvas in self.canvases():
            canvas.hovered.connect(partial(self._on_hover, canvas))
        self.source_view.set_heat_visible(self.act_heat.isChecked())

    def canvases(self) -> list[ImageCanvas]:
        return [
            self.source_view,
            self.preview_view.canvas,
            self.wrap_view.canvas,
            self.tile_view.canvas,
            *self.overlap_panel.views.values(),
            self.quilt_view.sample,
            self.quilt_view.target,
            self.quilt_view.output,
            self.quilt_view.inspector,
            self.wang_view.source,
            self.wang_view.tiles,
            self.wang_view.preview,
        ]

    # ------------------------------------------------------------------ messages
    @Slot(str, str)
    def show_message(self, level: str, text: str, actions=()) -> None:
        """Tell the user something without blocking (banner + status bar + log)."""
        text = params.editor_words(text)
        self.messages.append((level, text))
        getattr(log, {"error": "error", "warning": "warning"}.get(level, "info"))(text)
        if actions or level != "info" or not self.message_bar.waiting_for_answer():
            self.message_bar.show_message(level, text, actions)
        self.statusBar().showMessage(text, 10_000)

    @Slot(str)
    def _clear_status_message(self, text: str) -> None:
        """The banner's message closed: its copy in the status bar goes too (not a newer one)."""
        if self.statusBar().currentMessage() == text:
            self.statusBar().clearMessage()

    def last_message(self, level: str | None = None) -> str:
        for lv, text in reversed(self.messages):
            if level is None or lv == level:
                return text
        return ""

    @Slot()
    def _on_tile_size_edited(self) -> None:
        """A new tile size: search where a tile of that size sits best."""
        if self.doc.has_source:
            self.pipeline.find_template()

    @Slot()
    def _fill_recent_menu(self) -> None:
        self.files.fill_recent_menu(self.recent_menu)

    @Slot()
    def _on_image_opened(self) -> None:
        self.tabs.setCurrentWidget(self.source_view)

    def open_initial(self, path: str | None) -> None:
        """Start-up: open ``path`` (image or project) or the bundled sample."""
        self.files.open_initial(path)

    # ------------------------------------------------------------------ drag and drop
    def dragEnterEvent(self, event) -> None:  # noqa: N802 - Qt API
        if any(u.isLocalFile() for u in event.mimeData().urls()):
            event.acceptProposedAction()

    def dropEvent(self, event) -> None:  # noqa: N802 - Qt API
        files = [u.toLocalFile() for u in event.mimeData().urls() if u.isLocalFile()]
        if files:
            event.acceptProposedAction()
            self.files.open_path(files[0])

    # ------------------------------------------------------------------ export
    def open_library_dialog(self, *_args) -> None:
        path = self.files.ask_library_path()
        if path:
            self.open_library(path)

    def open_library(self, path: str):
        """Show the library in ``path`` in the Library dock (read in the background)."""
        dock = self.docks["library"]
        dock.show()
        dock.raise_()
        # a list to browse: the lower half of the centre, not the gallery's strip of thumbnails
        self.resizeDocks([dock], [self.height() // 2], Qt.Orientation.Vertical)
        return self.library_view.load(path)

    def export_dialog(self, *_args, wang: bool | None = None) -> None:
        """The export dialog of the tile set (``wang``: the Wang set; None: the Wang set when
        its tab is in front)."""
        from quilt_gui.widgets.export_dialog import ExportDialog

        if wang is None:
            wang = self.tabs.currentWidget() is self.wang_view
        w = self.doc.wang
        if wang and not w.complete:
            made = f" ({len(w.tiles)} of {w.count} tiles made)" if w.tiles else ""
            self.show_message("warning", f"Nothing to export yet: generate the Wang set{made}.")
            return
        if wang and w.stale:  # a moved sample's or a heal's tiles are not made yet
            self.show_message("warning", f"Wait for the rebuild of {len(w.stale)} Wang tiles.")
            return
        if not wang and not self.doc.tileset.candidates:
            self.show_message(
                "warning", "Nothing to export yet: generate candidates and pick the tiles to keep."
            )
            return
        dlg = getattr(self, "_export_dialog", None)
        if dlg is None:
            dlg = ExportDialog(self.doc, self.jobs, self)
            dlg.message.connect(self.show_message)
            self._export_dialog = dlg
        dlg.refresh(wang=wang)
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
        if self.doc.tileset.candidates[index].locked:
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
        self.pipeline.run_quilt(may_replace=self.files.may_replace_output)

    def _clear_painted(self, *_args) -> None:
        self.source_view.painter.clear_painted()

    def run_transfer(self, *_args) -> None:
        self.tabs.setCurrentWidget(self.quilt_view)
        self.pipeline.run_transfer(may_replace=self.files.may_replace_output)

    @Slot(int)
    def _on_tab_changed(self, _index: int) -> None:
        quilting, wang = (self.tabs.currentWidget() is v for v in (self.quilt_view, self.wang_view))
        self.doc.set_workflow("quilting" if quilting else "wang" if wang else "tileset")
        save_as = QKeySequence(QKeySequence.StandardKey.SaveAs)  # on the Quilting tab: Save output
        self.act_save_as.setShortcut(QKeySequence() if quilting else save_as)
        self.act_save_output.setShortcut(save_as if quilting else QKeySequence())
        for act, key in ((self.act_generate, "Ctrl+G"), (self.act_reroll_layout, "Ctrl+R")):
            act.setShortcut("" if wang else key)  # the Wang tab's buttons of those names take them
        groups = QUILT_GROUPS if quilting else WANG_GROUPS if wang else TILESET_GROUPS
        self.params_panel.show_groups(groups)
        self._show_tileset_docks(not quilting and not wang)
        self._show_criteria()

    def _show_tileset_docks(self, shown: bool) -> None:
        """The Wang and Quilting tabs hide the tile set's docks; back on the other tabs, the
        ones the user had left open there come back (and closed ones stay closed)."""
        docks = [self.docks[key] for key in ("overlaps", "tile", "gallery")]
        if self._left_open is None and not shown:
            self._left_open = [not dock.isHidden() for dock in docks]
        for dock, was_open in zip(docks, self._left_open or [], strict=False):
            dock.setVisible(shown and was_open)
        if shown:
            self._left_open = None

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

    def show_help(self) -> ShortcutSheet:
        """Help ▸ Keyboard and mouse: the shortcut sheet (non-modal)."""
        return self._show_dialog("shortcuts", lambda: ShortcutSheet(self.actions(), self))

    def show_getting_started(self) -> GettingStarted:
        return self._show_dialog("getting_started", lambda: GettingStarted(self))

    def _show_dialog(self, key: str, make):
        dlg = self._help.get(key)
        if dlg is None:
            dlg = self._help[key] = make()
        dlg.show()
        dlg.raise_()
        return dlg

    # ------------------------------------------------------------------ status
    def _on_hover(self, canvas: ImageCanvas, px) -> None:
        depth = self.doc.source.bit_depth if self.doc.source else 8  # every view shows its pixels
        self.pixel_label.setText(canvas.hover_text(px, depth))

    @Slot(object)
    def _on_seam_updated(self, update) -> None:
        self._criteria[update.which] = float(update.seam.criterion)
        self._show_criteria()

    @Slot()
    def _on_seamless_changed(self) -> None:
        s = self.doc.tileset.seamless
        self._criteria = {} if s is None else dict(s.criterion)
        self._show_criteria()
        self._update_actions()

    @Slot()
    def _show_criteria(self) -> None:
        """The seam criterion of what is in front: the template's seams, or the inspected
        quilting block's cut in the Quilting tab; none in the Wang tab (no template there)."""
        if self.tabs.currentWidget() is self.wang_view:
            self.criterion_label.setText("")
            return
        if self.tabs.currentWidget() is self.quilt_view:
            rec = self.quilt_view.selected_block()
            has_cut = rec is not None and len(rec.path)
            text = f"block #{rec.index + 1} seam {rec.criterion:.3f}" if has_cut else ""
            self.criterion_label.setText(text)
            return
        parts = [f"{k[0].upper()} {v:.3f}" for k, v in sorted(self._criteria.items())]
        s = self.doc.tileset.seamless
        made = self.overlap_panel.watch.variant_text() or (s and describe_seam(s.seam))
        text = "seam " + " · ".join(parts) if parts else ""
        self.criterion_label.setText(f"{text} — {made}" if parts and made else text)

    @Slot()
    def _update_title(self, *_args) -> None:
        name = Path(self.doc.project_path).name if self.doc.project_path else self.doc.name
        self.setWindowTitle(f"{name}[*] — {settings.APP_NAME}")
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
        self.act_generate.setEnabled(has and self.doc.tileset.seamless is not None)
        self.act_export.setEnabled(bool(self.doc.tileset.candidates) or self.doc.wang.complete)
        self.act_export_seamless.setEnabled(self.doc.tileset.seamless is not None)
        self.act_save_output.setEnabled(self.doc.quilting.finished_output is not None)
        self.act_reroll_layout.setEnabled(bool(self.doc.tileset.picks))
        n = len(self.doc.tileset.candidates)
        title = f"Candidates — {len(self.doc.tileset.picks)} of {n} picked" if n else "Candidates"
        if self.doc.tileset.candidates_outdated:
            title += " — made from an earlier template (Generate to update)"
        self.docks["gallery"].setWindowTitle(title)

    # ------------------------------------------------------------------ closing
    def closeEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self.files.closing:  # closed before (a second close, e.g. at the end of a test)
            event.accept()
            return
        if not self.files.confirm_discard():
            event.ignore()
            return
        self.files.stop_autosave()
        self.pipeline.shutdown()
        self.jobs.shutdown(3000)
        self.files.remove_recovery_file()
        settings.set("window_geometry", self.saveGeometry())
        self._show_tileset_docks(True)  # the state saved as the Source tab has it (reopens there)
        settings.set("window_state", self.saveState())
        settings.set("parameters", self.doc.params)
        for dlg in self._dialogs.values():
            dlg.close()
        event.accept()
        super().closeEvent(event)
