"""The parameters panel, built from :data:`quilt_gui.params.PARAMS`.

Every widget edits the document through :meth:`Document.set_param`; a slider drag shares
one merge id, so it is one undo step. Document changes (undo, project load) update the
widgets with their signals blocked.
"""

from __future__ import annotations

from functools import partial

from PySide6.QtCore import Qt, Slot
from PySide6.QtWidgets import (
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
    QToolButton,
    QVBoxLayout,
    QWidget,
)
from superqt import QLabeledDoubleSlider, QLabeledSlider
from superqt.utils import signals_blocked

from quilt_gui import params
from quilt_gui.commands import new_merge_id
from quilt_gui.document import Document

#: Integer parameters edited with a slider (the rest use spin boxes).
SLIDERS = frozenset(
    {
        "overlap",
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
    "Template",
    "Seam",
    MATERIALS,
    "Seam options",
    "Candidates",
    "Preview",
    "Exclusion",
)
QUILT_GROUPS = ("Quilting", "Exclusion", "Seam options", "Transfer")


class ParamsPanel(QScrollArea):
    """Group boxes of parameter widgets plus the actions of each step."""

    def __init__(self, doc: Document, actions: dict[str, list] | None = None, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.widgets: dict[str, QWidget] = {}
        self.groups: dict[str, QGroupBox] = {}
        self._merge: dict[str, int] = {}
        body = QWidget()
        lay = QVBoxLayout(body)
        lay.setContentsMargins(6, 6, 6, 6)
        for group in params.GROUPS:
            box = QGroupBox(group)
            form = QFormLayout(box)
            form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
            form.setLabelAlignment(Qt.AlignmentFlag.AlignRight)
            for p in params.PARAMS:
                if p.group != group:
                    continue
                w = self._make_widget(p)
                w.setToolTip(p.tip)
                label = QLabel(p.label)
                label.setToolTip(p.tip)
                form.addRow(label, w)
                self.widgets[p.key] = w
            buttons = (actions or {}).get(group, [])
            if buttons:
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
            if group == "Seam":
                self.materials = MaterialWeights(doc)
                lay.addWidget(self.materials)
                self.groups[MATERIALS] = self.materials
        lay.addStretch(1)
        self.setWidget(body)
        self.setMinimumWidth(body.sizeHint().width() + 24)
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self._quilting = False
        doc.params_changed.connect(self._on_params_changed)
        self._on_params_changed(frozenset(params.DEFAULTS))

    def show_groups(self, groups) -> None:
        """Show only these groups (the tile-set or the quilting mode)."""
        for name, box in self.groups.items():
            box.setVisible(name in groups)
        self.materials.wanted = MATERIALS in groups
        self.materials.refresh()
        self._quilting = "Quilting" in groups
        self._enable_seam_options()

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
        for key in params.SEAM_OPTION_KEYS | {"width", "rho", "q_width", "q_rho"}:
            w, tip = self.widgets[key], params.BY_KEY[key].tip
            w.setEnabled(key not in unused)
            w.setToolTip(f"{tip}\n({unused[key]})" if key in unused else tip)

    # ------------------------------------------------------------------ widgets
    def _make_widget(self, p: params.Param) -> QWidget:
        key = p.key
        if p.choices:
            w = QComboBox()
            w.addItems([str(c) for c in p.choices])
            w.currentTextChanged.connect(partial(self._edit, key))
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

    def _edit(self, key: str, value) -> None:
        self.doc.set_param(key, value, merge_id=self._merge.get(key))

    def value(self, key: str):
        """What the widget of ``key`` shows (for tests)."""
        w = self.widgets[key]
        if isinstance(w, QComboBox):
            return w.currentText()
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
                    w.setCurrentText(str(v))
                elif isinstance(w, QCheckBox):
                    w.setChecked(bool(v))
                elif isinstance(w, QLineEdit):
                    w.setText(str(v))
                else:
                    w.setValue(v)
        if keys & {"method", "q_method", "blend", "q_blend"}:
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
