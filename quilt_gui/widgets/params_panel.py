"""The parameters panel, built from :data:`quilt_gui.params.PARAMS`.

Every widget edits the document through :meth:`Document.set_param`; a slider drag shares
one merge id, so it is one undo step. Document changes (undo, project load) update the
widgets with their signals blocked.
"""

from __future__ import annotations

from functools import partial

from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtGui import QPalette
from PySide6.QtWidgets import (
    QButtonGroup,
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QScrollArea,
    QSizePolicy,
    QSpinBox,
    QStyle,
    QStyleOptionComboBox,
    QStylePainter,
    QToolButton,
    QVBoxLayout,
    QWidget,
)
from superqt import QLabeledDoubleSlider, QLabeledSlider
from superqt.utils import signals_blocked

from quilt_gui import params, settings
from quilt_gui.commands import new_merge_id
from quilt_gui.document import Document
from quilt_gui.param_table import ADVANCED, BASIC

#: Integer parameters edited with a slider (the rest use spin boxes).
SLIDERS = frozenset(
    {
        "o_max",
        "max_run",
        "width",
        "rho",
        "margin",
        "neighbourhood",
        "iterations",
        "q_width",
        "q_rho",
    }
)
MATERIALS = "Material maps"
TILESET_GROUPS = (
    "Tile",
    "Seams",
    MATERIALS,
    "Seam options",
    "Candidates",
    "Preview",
    "Exclusion",
    "Heal",
)
#: the groups the Wang set uses: its cuts (seams, their options, the material maps' weights) and
#: the pixels never to use; its own options are on the Wang tab
WANG_GROUPS = ("Seams", MATERIALS, "Seam options", "Exclusion")
#: group titles on screen, where they differ from the group's name
GROUP_TITLES = {"Exclusion": "Pixels never to use", "Heal": "Heal the source"}
QUILT_GROUPS = ("Quilting", "Exclusion", "Seam options", "Transfer")
VIEWS = (BASIC, ADVANCED)


class ElidingComboBox(QComboBox):
    """A choice box that ends a name too long for it with "…" (the narrow panel cut "Cut
    across, row by row" to "Cut across, row by rov"); the list shows the whole names."""

    def shown_text(self) -> str:
        opt = QStyleOptionComboBox()
        self.initStyleOption(opt)
        field = self.style().subControlRect(
            QStyle.ComplexControl.CC_ComboBox, opt, QStyle.SubControl.SC_ComboBoxEditField, self
        )
        return self.fontMetrics().elidedText(
            self.currentText(), Qt.TextElideMode.ElideRight, max(0, field.width() - 2)
        )

    def paintEvent(self, _event) -> None:  # noqa: N802 - Qt API
        painter = QStylePainter(self)
        painter.setPen(self.palette().color(QPalette.ColorRole.Text))
        opt = QStyleOptionComboBox()
        self.initStyleOption(opt)
        painter.drawComplexControl(QStyle.ComplexControl.CC_ComboBox, opt)
        opt.currentText = self.shown_text()
        painter.drawControl(QStyle.ControlElement.CE_ComboBoxLabel, opt)


class ParamsPanel(QWidget):
    """Group boxes of parameter widgets plus the actions of each step, in a Basic view (what
    most photos need) or an Advanced one (everything), and a Reset to defaults."""

    tile_size_edited = Signal()  # the person chose another tile size (not an undo)

    def __init__(self, doc: Document, actions: dict[str, list] | None = None, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.widgets: dict[str, QWidget] = {}
        self.labels: dict[str, QLabel] = {}
        self.groups: dict[str, QGroupBox] = {}
        self._forms: dict[str, QFormLayout] = {}
        self._has_actions: set[str] = set()
        self._merge: dict[str, int] = {}
        self._shown: tuple = TILESET_GROUPS
        body = QWidget()
        lay = QVBoxLayout(body)
        lay.setContentsMargins(6, 6, 6, 6)
        names = list(params.GROUPS)
        for group in actions or {}:  # groups of actions alone (Heal), after the exclusion
            if group not in names:
                names.insert(names.index("Exclusion") + 1, group)
        for group in names:
            box = QGroupBox(GROUP_TITLES.get(group, group))
            form = QFormLayout(box)
            form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
            form.setLabelAlignment(Qt.AlignmentFlag.AlignRight)
            for p in params.PARAMS:
                if p.group != group:
                    continue
                w = self._make_widget(p)
                w.setToolTip(p.tooltip)
                label = QLabel(p.label)
                label.setToolTip(p.tooltip)
                form.addRow(label, w)
                self.widgets[p.key] = w
                self.labels[p.key] = label
                if p.key == "blend":  # what Flatten lighting's Auto uses instead, said here
                    self.tone_hint = QLabel()
                    self.tone_hint.setWordWrap(True)
                    form.addRow(self.tone_hint)
                    form.setRowVisible(self.tone_hint, False)
            buttons = (actions or {}).get(group, [])
            if buttons:
                self._has_actions.add(group)
                row = QHBoxLayout()
                for action in buttons:
                    b = QToolButton()
                    b.setDefaultAction(action)
                    b.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
                    b.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
                    row.addWidget(b)
                form.addRow(row)
            lay.addWidget(box)
            self.groups[group] = box
            self._forms[group] = form
            if group == "Seams":
                self.materials = MaterialWeights(doc)
                lay.addWidget(self.materials)
                self.groups[MATERIALS] = self.materials
        lay.addStretch(1)
        self.scroll = QScrollArea()
        self.scroll.setWidget(body)
        self.scroll.setWidgetResizable(True)
        self.scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.scroll.setFrameShape(QScrollArea.Shape.NoFrame)
        bar = QHBoxLayout()
        bar.setContentsMargins(6, 4, 6, 0)
        self.view_buttons = QButtonGroup(self)
        for i, name in enumerate(VIEWS):
            b = QToolButton()
            b.setText(name)
            b.setCheckable(True)
            b.setToolTip("Only what most photos need" if name == BASIC else "Every parameter")
            self.view_buttons.addButton(b, i)
            bar.addWidget(b)
        self.view_buttons.idClicked.connect(self._on_view_clicked)
        bar.addStretch(1)
        self.reset_button = QToolButton()
        self.reset_button.setText("Reset to defaults")
        self.reset_button.setToolTip(
            "Every parameter shown here back to its default (Auto sizes follow the image); "
            "one undo step"
        )
        self.reset_button.clicked.connect(self.reset_to_defaults)
        bar.addWidget(self.reset_button)
        outer = QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        outer.addLayout(bar)
        outer.addWidget(self.scroll, 1)
        self.setMinimumWidth(body.sizeHint().width() + 24)
        self._quilting = False
        self.view = settings.get("params_view") if settings.get("params_view") in VIEWS else BASIC
        self.view_buttons.button(VIEWS.index(self.view)).setChecked(True)
        doc.params_changed.connect(self._on_params_changed)
        doc.tileset.tone_changed.connect(self._on_tone_changed)
        self._on_params_changed(frozenset(params.DEFAULTS))

    # ------------------------------------------------------------------ what is shown
    def show_groups(self, groups) -> None:
        """Show only these groups (the tile-set or the quilting mode)."""
        self._shown = tuple(groups)
        self.materials.wanted = MATERIALS in groups
        self.materials.refresh()
        self._quilting = "Quilting" in groups
        self._apply_view()
        self._enable_seam_options()
        self._on_tone_changed()

    def set_view(self, view: str) -> None:
        """Basic (the parameters most photos need) or Advanced (every parameter)."""
        self.view = view
        self.view_buttons.button(VIEWS.index(view)).setChecked(True)
        settings.set("params_view", view)
        self._apply_view()

    @Slot(int)
    def _on_view_clicked(self, index: int) -> None:
        self.set_view(VIEWS[index])

    def _apply_view(self) -> None:
        basic = self.view == BASIC
        for p in params.PARAMS:
            self._forms[p.group].setRowVisible(self.widgets[p.key], p.basic or not basic)
        for name, box in self.groups.items():
            if name == MATERIALS:
                continue
            has_basic = any(p.basic for p in params.PARAMS if p.group == name)
            wanted = not basic or has_basic or name in self._has_actions
            box.setVisible(name in self._shown and wanted)

    def shown_keys(self) -> list[str]:
        """The parameters on screen (tests, screenshots)."""
        return [k for k, w in self.widgets.items() if w.isVisibleTo(self)]

    @Slot()
    def reset_to_defaults(self) -> None:
        """The parameters of the shown groups back to their defaults, as one undo step."""
        keys = [p.key for p in params.PARAMS if p.group in self._shown and p.key != "brush"]
        self.doc.set_params(
            {k: params.DEFAULTS[k] for k in keys}, text="Reset parameters to defaults"
        )

    def _enable_seam_options(self) -> None:
        """Only the options in use are editable: those of the seam method of the mode, the
        feather width with feather blending, rho with adaptive blending."""
        p = self.doc.params
        method = p["q_method" if self._quilting else "method"]
        unused = {
            k: f"not used by {method}"
            for k in (q.key for q in params.PARAMS if q.group == "Seam options")
            if k not in params.seam_option_keys(method)
        }
        for blend, width, rho in (("blend", "width", "rho"), ("q_blend", "q_width", "q_rho")):
            if p[blend] != "feather":
                unused[width] = "only for feather blending"
            if p[blend] != "adaptive":
                unused[rho] = "only for adaptive blending"
        if p["tile_size"] != params.ANY:
            unused["tile_min"] = unused["tile_max"] = "only for Tile size Any"
        for key in (
            params.SEAM_OPTION_KEYS
            | {"width", "rho", "q_width", "q_rho"}
            | {
                "tile_min",
                "tile_max",
            }
        ):
            w, tip = self.widgets[key], params.BY_KEY[key].tooltip
            w.setEnabled(key not in unused)
            w.setToolTip(f"{tip}\n({unused[key]})" if key in unused else tip)

    @Slot()
    def _on_tone_changed(self) -> None:
        """Under Seam blending: the blend Flatten lighting's Auto uses for this photo instead of
        the one chosen (the box keeps the choice, which applies again with Flatten lighting Off);
        not for a Wang set (Auto tone leaves it alone: the choice applies)."""
        blend = self.doc.tileset.auto_blend if "Tile" in self._shown else None
        if blend is not None:
            name = params.BY_KEY["blend"].choice_label(blend)
            self.tone_hint.setText(
                f"<i>Uneven lighting: Auto tone uses “{name}” for this photo "
                "(Flatten lighting: Off keeps the choice above)</i>"
            )
        self._forms["Seams"].setRowVisible(self.tone_hint, blend is not None)

    # ------------------------------------------------------------------ widgets
    def _make_widget(self, p: params.Param) -> QWidget:
        key = p.key
        if p.choices:
            w = ElidingComboBox()
            w.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
            w.setMinimumContentsLength(12)  # long choice names must not widen the panel
            for c in p.choices:
                w.addItem(p.choice_label(c), c)
            w.currentIndexChanged.connect(partial(self._edit_choice, key, w))
            return w
        if isinstance(p.default, bool):
            w = QCheckBox()
            w.toggled.connect(partial(self._edit, key))
            return w
        if isinstance(p.default, str):
            w = QLineEdit()
            w.setPlaceholderText("none")
            w.editingFinished.connect(partial(self._edit_text, key, w))
            return w
        if isinstance(p.default, float):
            w = QLabeledDoubleSlider(Qt.Orientation.Horizontal)
            w.setRange(p.minimum, p.maximum)
            w.setSingleStep(p.step)
            w.setDecimals(p.decimals)
        elif key in SLIDERS:
            w = QLabeledSlider(Qt.Orientation.Horizontal)
            w.setRange(int(p.minimum), int(p.maximum))
        else:
            w = QSpinBox()
            w.setRange(int(p.minimum), int(p.maximum))
            w.setSpecialValueText(p.special)
            w.setKeyboardTracking(False)
            w.setAccelerated(True)
            w.valueChanged.connect(partial(self._edit, key))
            return w
        w.sliderPressed.connect(partial(self._drag_started, key))
        w.sliderReleased.connect(partial(self._drag_ended, key))
        w.valueChanged.connect(partial(self._edit, key))
        return w

    def _drag_started(self, key: str) -> None:
        self._merge[key] = new_merge_id()

    def _drag_ended(self, key: str) -> None:
        self._merge.pop(key, None)

    def _edit_text(self, key: str, widget) -> None:
        try:
            self._edit(key, widget.text())
        except ValueError:
            widget.setText(self.doc.params[key])  # not a colour: back to the valid value

    def _edit_choice(self, key: str, widget: QComboBox, _index: int) -> None:
        self._edit(key, widget.currentData())

    def _edit(self, key: str, value) -> None:
        before = self.doc.params[key]
        self.doc.set_param(key, value, merge_id=self._merge.get(key))
        if key in params.TILE_SIZE_KEYS and self.doc.params[key] != before:
            self.tile_size_edited.emit()

    def value(self, key: str):
        """What the widget of ``key`` shows (for tests)."""
        w = self.widgets[key]
        if isinstance(w, QComboBox):
            return w.currentData()
        if isinstance(w, QCheckBox):
            return w.isChecked()
        if isinstance(w, QLineEdit):
            return w.text()
        return w.value()

    @Slot(object)
    def _on_params_changed(self, keys) -> None:
        for key in keys:
            w = self.widgets.get(key)
            if w is None:
                continue
            v = self.doc.params[key]
            with signals_blocked(w):
                if isinstance(w, QComboBox):
                    w.setCurrentIndex(w.findData(v))
                elif isinstance(w, QCheckBox):
                    w.setChecked(bool(v))
                elif isinstance(w, QLineEdit):
                    w.setText(str(v))
                else:
                    w.setValue(v)
        if keys & {"method", "q_method", "blend", "q_blend", "tile_size"}:
            self._enable_seam_options()


class MaterialWeights(QGroupBox):
    """How much each material map counts in the seam error (shown once a map is attached).

    Default: the main map alone (weight 1, the others 0); a height or normal map with some
    weight steers the cuts around its own edges too. Every change is one undo step.
    """

    def __init__(self, doc: Document, parent=None) -> None:
        super().__init__(MATERIALS, parent)
        self.doc = doc
        self.wanted = True  # the tile-set mode shows it (when there is more than one map)
        self.spins: dict[str, QDoubleSpinBox] = {}
        self.form = QFormLayout(self)
        self.form.setLabelAlignment(Qt.AlignmentFlag.AlignRight)
        self.setToolTip(
            "Seam error = weighted mix of the maps' errors; the cuts, patches and blends "
            "are applied to every map alike."
        )
        doc.source_changed.connect(self.refresh)
        doc.maps_changed.connect(self.refresh)
        doc.tileset.map_weights_changed.connect(self.refresh)
        self.refresh()

    @Slot()
    def refresh(self) -> None:
        src = self.doc.source
        names = list(src.maps) if src is not None else []
        if list(self.spins) != names:
            while self.form.rowCount():
                self.form.removeRow(0)
            self.spins = {}
            for name in names:
                spin = QDoubleSpinBox()
                spin.setRange(0.0, 10.0)
                spin.setSingleStep(0.1)
                spin.setDecimals(2)
                spin.setKeyboardTracking(False)
                spin.setToolTip(f"Weight of the {name} map in the seam error (0 = ignored)")
                spin.valueChanged.connect(partial(self._edit, name))
                kind = src.kinds.get(name, "")
                label = QLabel(f"{name} ({kind})" if kind and kind != name else name)
                self.form.addRow(label, spin)
                self.spins[name] = spin
        for name, spin in self.spins.items():
            with signals_blocked(spin):
                spin.setValue(self.doc.tileset.map_weight(name))
        self.setVisible(self.wanted and len(names) > 1)

    def _edit(self, name: str, value: float) -> None:
        self.doc.tileset.set_map_weight(name, value)
