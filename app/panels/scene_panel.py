"""Scene editor: persons (trajectory class a–e with parameters, or waypoints), clutter density,
static reflectors, AOI and seed; bound both ways to the :class:`SceneModel` document."""

from __future__ import annotations

import random

from PySide6 import QtCore, QtGui, QtWidgets

from app.models import SceneModel
from app.person_colours import person_colour
from core.config import PAPER_CLUTTER_DENSITY_PER_M2
from core.errors import InputError
from core.limits import MAX_PERSONS, PERSON_HEIGHT_RANGE_M
from core.scene.scene import DEFAULT_PERSON_MODEL, PERSON_MODELS, person_model_kind
from core.scene.walking import DEFAULT_HEIGHT_M

CLASS_NAMES = {
    "a": "a — straight line (along x or y)",
    "b": "b — straight line toward the radar",
    "c": "c — random turns",
    "d": "d — random stops",
    "e": "e — circle",
}

DEFAULT_WAYPOINT_SPEED_MPS = 1.2


def _dspin(lo, hi, decimals, suffix="", name="") -> QtWidgets.QDoubleSpinBox:
    s = QtWidgets.QDoubleSpinBox()
    s.setRange(lo, hi)
    s.setDecimals(decimals)
    s.setKeyboardTracking(False)
    if suffix:
        s.setSuffix(f" {suffix}")
    if name:
        s.setObjectName(name)
    return s


class XYTable(QtWidgets.QTableWidget):
    """A small numeric table (rows of floats) with add/remove. The last ``n_optional`` columns
    may be left blank: a row ends at its first blank optional cell (a waypoint's hold time)."""

    edited = QtCore.Signal()

    def __init__(self, headers: list[str], name: str, n_optional: int = 0) -> None:
        super().__init__(0, len(headers))
        self.n_optional = n_optional
        self.setObjectName(name)
        self.setHorizontalHeaderLabels(headers)
        self.horizontalHeader().setSectionResizeMode(QtWidgets.QHeaderView.Stretch)
        self.verticalHeader().setDefaultSectionSize(22)
        self.setMinimumHeight(110)
        self.itemChanged.connect(lambda _item: self.edited.emit())

    def set_rows(self, rows: list[list[float]]) -> None:
        self.blockSignals(True)
        self.setRowCount(len(rows))
        for i, row in enumerate(rows):
            for j in range(self.columnCount()):
                text = f"{float(row[j]):.3f}" if j < len(row) else ""
                self.setItem(i, j, QtWidgets.QTableWidgetItem(text))
        self.blockSignals(False)

    def rows(self) -> list[list[float]]:
        out = []
        for i in range(self.rowCount()):
            row = []
            for j in range(self.columnCount()):
                item = self.item(i, j)
                text = item.text().strip() if item is not None else ""
                if not text and j >= self.columnCount() - self.n_optional:
                    break
                try:
                    row.append(float(text))
                except ValueError:
                    header = self.horizontalHeaderItem(j).text()
                    raise InputError(
                        f"row {i + 1}, {header}: {text!r} is not a number", self.objectName()
                    ) from None
            out.append(row)
        return out


class ScenePanel(QtWidgets.QWidget):
    """Edits the scene document; every edit is validated by core before it is adopted."""

    error = QtCore.Signal(str)
    draw_mode_changed = QtCore.Signal(bool)

    def __init__(self, model: SceneModel, engine, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("scenePanel")
        self.model = model
        self.engine = engine
        outer = QtWidgets.QVBoxLayout(self)
        outer.addWidget(self._scene_box())
        outer.addWidget(self._persons_box(engine))
        outer.addWidget(self._reflectors_box())
        outer.addStretch(1)

        self._wire(model)

    # ---- construction ------------------------------------------------------------------------
    def _scene_box(self) -> QtWidgets.QGroupBox:
        """Seed, clutter density and the area of interest."""
        general = QtWidgets.QGroupBox("Scene")
        form = QtWidgets.QFormLayout(general)
        self.seed = QtWidgets.QSpinBox()
        self.seed.setObjectName("sceneSeed")
        self.seed.setRange(0, 2**31 - 1)
        self.seed.setKeyboardTracking(False)
        self.clutter = _dspin(0.0, 1.0, 4, "/m²", "clutterDensity")
        self.clutter.setSingleStep(0.005)
        self.min_range = _dspin(0.1, 50.0, 2, "m", "aoiMinRange")
        self.max_range = _dspin(0.5, 100.0, 2, "m", "aoiMaxRange")
        self.max_az = _dspin(1.0, 90.0, 1, "°", "aoiMaxAzimuth")
        form.addRow("seed", self.seed)
        form.addRow("clutter density λ", self.clutter)
        form.addRow("AOI min range", self.min_range)
        form.addRow("AOI max range", self.max_range)
        form.addRow("AOI max |azimuth|", self.max_az)
        return general

    def _persons_box(self, engine) -> QtWidgets.QGroupBox:
        """The person list and the selected person's trajectory, RCS and body model."""
        persons = QtWidgets.QGroupBox("Persons")
        pl = QtWidgets.QVBoxLayout(persons)
        self.person_list = QtWidgets.QListWidget()
        self.person_list.setObjectName("personList")
        self.person_list.setMaximumHeight(80)
        pl.addWidget(self.person_list)
        row = QtWidgets.QHBoxLayout()
        self.add_class_button = QtWidgets.QPushButton("+ class")
        self.add_class_button.setObjectName("addClassPerson")
        self.add_wp_button = QtWidgets.QPushButton("+ waypoints")
        self.add_wp_button.setObjectName("addWaypointPerson")
        self.remove_button = QtWidgets.QPushButton("remove")
        self.remove_button.setObjectName("removePerson")
        for b in (self.add_class_button, self.add_wp_button, self.remove_button):
            row.addWidget(b)
        pl.addLayout(row)

        self.stack = QtWidgets.QStackedWidget()
        self.stack.addWidget(self._class_page(engine))
        self.stack.addWidget(self._waypoint_page())
        # explicit profile page
        self.profile_label = QtWidgets.QLabel("explicit eq. (6) profile (edit the JSON file)")
        self.profile_label.setWordWrap(True)
        self.stack.addWidget(self.profile_label)
        pl.addWidget(self.stack)
        rcs_row = QtWidgets.QHBoxLayout()
        self.fixed_rcs = QtWidgets.QCheckBox("fixed RCS")
        self.fixed_rcs.setObjectName("fixedRcs")
        self.rcs = _dspin(-40.0, 30.0, 1, "dBsm", "personRcs")
        rcs_row.addWidget(self.fixed_rcs)
        rcs_row.addWidget(self.rcs, 1)
        pl.addLayout(rcs_row)
        model_row = QtWidgets.QHBoxLayout()
        model_row.addWidget(QtWidgets.QLabel("model"))
        self.person_model = QtWidgets.QComboBox()
        self.person_model.setObjectName("personModel")
        self.person_model.addItems(list(PERSON_MODELS))
        self.person_model.setToolTip(
            "point: the paper's one scatterer; blob: 5 scatterers with micro-Doppler; "
            "walking: 17 segments driven by Boulic's gait model (docs/scenes.md)"
        )
        self.height = _dspin(*PERSON_HEIGHT_RANGE_M, 2, "m", "personHeight")
        self.height.setToolTip("body height of the walking model")
        model_row.addWidget(self.person_model, 1)
        model_row.addWidget(self.height, 1)
        pl.addLayout(model_row)
        return persons

    def _class_page(self, engine) -> QtWidgets.QWidget:
        """A person of a trajectory class: the class, its seed and its parameters."""
        class_page = QtWidgets.QWidget()
        cf = QtWidgets.QFormLayout(class_page)
        cf.setContentsMargins(0, 0, 0, 0)
        self.class_combo = QtWidgets.QComboBox()
        self.class_combo.setObjectName("classCombo")
        for key, name in CLASS_NAMES.items():
            self.class_combo.addItem(name, key)
        seed_row = QtWidgets.QHBoxLayout()
        self.person_seed = QtWidgets.QSpinBox()
        self.person_seed.setObjectName("personSeed")
        self.person_seed.setRange(0, 2**31 - 1)
        self.person_seed.setKeyboardTracking(False)
        self.regen_button = QtWidgets.QPushButton("Regenerate")
        self.regen_button.setObjectName("regenerateButton")
        self.regen_button.setToolTip("Draw a new trajectory of this class (new seed)")
        seed_row.addWidget(self.person_seed, 1)
        seed_row.addWidget(self.regen_button)
        cf.addRow("class", self.class_combo)
        cf.addRow("seed", seed_row)
        self.class_params: dict[str, QtWidgets.QDoubleSpinBox] = {}
        for spec in engine.class_param_specs():
            spin = _dspin(
                spec.low - spec.step, spec.high, spec.decimals, spec.unit, f"cp_{spec.name}"
            )
            spin.setSingleStep(spec.step)
            spin.setSpecialValueText("random")
            spin.setToolTip(f"{spec.help} ('random' lets the generator draw it)")
            spin.setValue(spin.minimum())
            spin.valueChanged.connect(self._on_class_edit)
            cf.addRow(spec.label, spin)
            self.class_params[spec.name] = spin
        return class_page

    def _waypoint_page(self) -> QtWidgets.QWidget:
        """A person on waypoints: the table and drawing on the top view."""
        wp_page = QtWidgets.QWidget()
        wl = QtWidgets.QVBoxLayout(wp_page)
        wl.setContentsMargins(0, 0, 0, 0)
        self.waypoints = XYTable(
            ["x [m]", "y [m]", "speed [m/s]", "hold [s]"], "waypointTable", n_optional=1
        )
        wl.addWidget(self.waypoints)
        wrow = QtWidgets.QHBoxLayout()
        self.draw_button = QtWidgets.QPushButton("Draw on top view")
        self.draw_button.setObjectName("drawWaypoints")
        self.draw_button.setCheckable(True)
        self.draw_button.setToolTip("Click in the top view to append waypoints; drag to move them")
        self.del_wp_button = QtWidgets.QPushButton("delete last")
        wrow.addWidget(self.draw_button)
        wrow.addWidget(self.del_wp_button)
        wl.addLayout(wrow)
        return wp_page

    def _reflectors_box(self) -> QtWidgets.QGroupBox:
        """The static reflectors (removed by the chain)."""
        refl = QtWidgets.QGroupBox("Static reflectors (removed by the chain)")
        rl = QtWidgets.QVBoxLayout(refl)
        self.reflectors = XYTable(["x [m]", "y [m]", "RCS [dBsm]"], "reflectorTable")
        self.reflectors.setMinimumHeight(80)
        rl.addWidget(self.reflectors)
        rrow = QtWidgets.QHBoxLayout()
        self.add_refl = QtWidgets.QPushButton("add")
        self.add_refl.setObjectName("addReflector")
        self.del_refl = QtWidgets.QPushButton("remove last")
        rrow.addWidget(self.add_refl)
        rrow.addWidget(self.del_refl)
        rl.addLayout(rrow)
        return refl

    def _wire(self, model: SceneModel) -> None:
        """Connect the fields to the scene model and back."""
        self.seed.valueChanged.connect(lambda v: self._edit(seed=int(v)))
        self.clutter.valueChanged.connect(lambda v: self._edit(clutter_density_per_m2=float(v)))
        for w in (self.min_range, self.max_range, self.max_az):
            w.valueChanged.connect(self._on_aoi)
        self.person_list.currentRowChanged.connect(self._on_select)
        self.add_class_button.clicked.connect(self._add_class_person)
        self.add_wp_button.clicked.connect(self._add_waypoint_person)
        self.remove_button.clicked.connect(self._remove_person)
        self.class_combo.currentIndexChanged.connect(self._on_class_edit)
        self.person_seed.valueChanged.connect(self._on_class_edit)
        self.regen_button.clicked.connect(self._regenerate)
        self.waypoints.edited.connect(self._on_waypoints_edit)
        self.del_wp_button.clicked.connect(self._delete_last_waypoint)
        self.draw_button.toggled.connect(self.draw_mode_changed)
        self.fixed_rcs.toggled.connect(self._on_rcs)
        self.rcs.valueChanged.connect(self._on_rcs)
        self.person_model.currentIndexChanged.connect(self._on_person_model)
        self.height.valueChanged.connect(self._on_person_model)
        self.reflectors.edited.connect(self._on_reflectors)
        self.add_refl.clicked.connect(self._add_reflector)
        self.del_refl.clicked.connect(self._delete_reflector)
        model.changed.connect(self.sync)
        model.selection_changed.connect(lambda _i: self.sync())
        self.sync()

    # ---- helpers ------------------------------------------------------------------------------
    def _try(self, fn, *args, **kwargs) -> bool:
        try:
            fn(*args, **kwargs)
            return True
        except InputError as exc:
            self.error.emit(str(exc))
            self.sync()
            return False

    def _edit(self, **kw) -> None:
        self._try(self.model.edit, **kw)

    def _on_aoi(self, *_args) -> None:
        aoi = {
            "min_range_m": self.min_range.value(),
            "max_range_m": self.max_range.value(),
            "max_azimuth_deg": self.max_az.value(),
        }
        self._edit(aoi=aoi)

    def _on_select(self, row: int) -> None:
        if row >= 0:
            self.model.select_person(row)

    def _current(self) -> tuple[int, dict]:
        i = self.model.selected_person
        return i, self.model.person(i)

    def _add_class_person(self) -> None:
        cls = self.class_combo.currentData() or "c"
        person = {
            "model": DEFAULT_PERSON_MODEL,
            "trajectory": {"class": cls, "seed": random.randrange(2**31 - 1)},
        }
        self._try(self.model.add_person, person)

    def _add_waypoint_person(self) -> None:
        person = {
            "model": DEFAULT_PERSON_MODEL,
            "trajectory": {"waypoints": [[-1.0, 3.0, 1.2], [1.0, 6.0, 1.2]]},
        }
        self._try(self.model.add_person, person)

    def _remove_person(self) -> None:
        self._try(self.model.remove_person, self.model.selected_person)

    def _class_trajectory(self, seed: int | None = None) -> dict:
        traj = {
            "class": self.class_combo.currentData(),
            "seed": int(self.person_seed.value() if seed is None else seed),
        }
        allowed = self.engine.class_param_names(traj["class"])
        values = {
            name: round(spin.value(), spin.decimals())
            for name, spin in self.class_params.items()
            if spin.value() > spin.minimum() and name in allowed
        }
        sx, sy = values.pop("start_x_m", None), values.pop("start_y_m", None)
        if (sx is None) != (sy is None):
            # one coordinate given: keep the other where the current trajectory starts
            scene = self.model.scene
            i = self.model.selected_person
            if scene is not None and i < len(scene.persons):
                x0, y0 = scene.persons[i].trajectory.position_m[0]
                sx = round(float(x0), 2) if sx is None else sx
                sy = round(float(y0), 2) if sy is None else sy
        if sx is not None and sy is not None:
            values["start_m"] = [sx, sy]
        traj.update(values)
        return traj

    def _on_class_edit(self, *_args) -> None:
        i, person = self._current()
        if "class" not in person["trajectory"]:
            return
        person["trajectory"] = self._class_trajectory()
        self._try(self.model.set_person, i, person)

    def _regenerate(self) -> None:
        i, person = self._current()
        if "class" not in person["trajectory"]:
            return
        person["trajectory"] = self._class_trajectory(seed=random.randrange(2**31 - 1))
        self._try(self.model.set_person, i, person)

    def _on_waypoints_edit(self) -> None:
        i, person = self._current()
        try:
            rows = self.waypoints.rows()
        except InputError as exc:
            self.error.emit(str(exc))
            self.sync()
            return
        person["trajectory"] = {"waypoints": rows}
        self._try(self.model.set_person, i, person)

    def set_waypoints(self, rows: list[list[float]]) -> bool:
        """Replace the selected person's waypoints (used by the top-view editor)."""
        i, person = self._current()
        if "waypoints" not in person["trajectory"]:
            return False
        person["trajectory"] = {"waypoints": rows}
        return self._try(self.model.set_person, i, person)

    def append_waypoint(self, x_m: float, y_m: float) -> bool:
        i, person = self._current()
        if "waypoints" not in person["trajectory"]:
            return False
        rows = list(person["trajectory"]["waypoints"])
        speed = rows[-1][2] if rows else DEFAULT_WAYPOINT_SPEED_MPS
        rows.append([round(x_m, 3), round(y_m, 3), speed])
        return self.set_waypoints(rows)

    def _delete_last_waypoint(self) -> None:
        i, person = self._current()
        rows = list(person["trajectory"].get("waypoints", []))
        if len(rows) > 2:
            self.set_waypoints(rows[:-1])
        else:
            self.error.emit("a drawn trajectory needs at least two waypoints")

    def _on_rcs(self, *_args) -> None:
        i, person = self._current()
        if self.fixed_rcs.isChecked():
            person["rcs_dbsm"] = self.rcs.value()
        else:
            person.pop("rcs_dbsm", None)
        self._try(self.model.set_person, i, person)

    def _on_person_model(self, *_args) -> None:
        i, person = self._current()
        kind = self.person_model.currentText()
        if kind == "point":
            person.pop("model", None)
        elif person_model_kind(person.get("model", "point")) != kind:
            person["model"] = kind
        if kind == "walking":
            person["height_m"] = round(self.height.value(), 2)
        else:
            person.pop("height_m", None)
            person.pop("gait_phase", None)
        self._try(self.model.set_person, i, person)

    def _on_reflectors(self) -> None:
        try:
            rows = self.reflectors.rows()
        except InputError as exc:
            self.error.emit(str(exc))
            self.sync()
            return
        self._edit(static_reflectors=[{"x_m": x, "y_m": y, "rcs_dbsm": r} for x, y, r in rows])

    def _add_reflector(self) -> None:
        refl = self.model.document.get("static_reflectors", [])
        refl.append({"x_m": 2.0, "y_m": 6.0, "rcs_dbsm": 10.0})
        self._edit(static_reflectors=refl)

    def _delete_reflector(self) -> None:
        refl = self.model.document.get("static_reflectors", [])
        if refl:
            self._edit(static_reflectors=refl[:-1])

    # ---- model → widgets -------------------------------------------------------------------------
    def sync(self) -> None:
        """Put the model's document on the widgets (their signals blocked meanwhile)."""
        doc = self.model.document
        if not doc:
            return
        widgets = [
            self.seed,
            self.clutter,
            self.min_range,
            self.max_range,
            self.max_az,
            self.person_list,
            self.class_combo,
            self.person_seed,
            self.fixed_rcs,
            self.rcs,
            self.person_model,
            self.height,
            *self.class_params.values(),
        ]
        for w in widgets:
            w.blockSignals(True)
        try:
            self._sync_scene_fields(doc)
            persons = doc.get("persons", [])
            self._sync_person_list(persons)
            sel = self.model.selected_person
            self.person_list.setCurrentRow(sel)
            self._sync_person(persons[sel] if persons else {"trajectory": {}})
            self.reflectors.set_rows(
                [
                    [r["x_m"], r["y_m"], r.get("rcs_dbsm", 10.0)]
                    for r in doc.get("static_reflectors", [])
                ]
            )
            self._sync_person_buttons(len(persons))
        finally:
            for w in widgets:
                w.blockSignals(False)
        if self.stack.currentIndex() != 1 and self.draw_button.isChecked():
            self.draw_button.setChecked(False)

    def _sync_scene_fields(self, doc: dict) -> None:
        """Seed, clutter density and area of interest (missing ones: the paper's)."""
        self.seed.setValue(int(doc.get("seed", 0)))
        self.clutter.setValue(
            float(doc.get("clutter_density_per_m2", PAPER_CLUTTER_DENSITY_PER_M2))
        )
        aoi = {**self.engine.default_aoi(), **doc.get("aoi", {})}
        self.min_range.setValue(aoi["min_range_m"])
        self.max_range.setValue(aoi["max_range_m"])
        self.max_az.setValue(aoi["max_azimuth_deg"])

    def _sync_person_list(self, persons: list) -> None:
        """One row per person: how its trajectory is given, with its colour."""
        self.person_list.clear()
        for k, p in enumerate(persons):
            t = p.get("trajectory", {})
            if "class" in t:
                desc = f"class {t['class']} (seed {t.get('seed', '–')})"
            elif "waypoints" in t:
                desc = f"drawn, {len(t['waypoints'])} waypoints"
            else:
                desc = "explicit profile"
            self.person_list.addItem(f"person {k + 1}: {desc}")
            swatch = QtGui.QPixmap(12, 12)
            swatch.fill(QtGui.QColor(*person_colour(k)))
            self.person_list.item(k).setIcon(QtGui.QIcon(swatch))

    def _sync_person(self, person: dict) -> None:
        """The selected person's trajectory page, RCS and person model."""
        t = person.get("trajectory", {})
        if "class" in t:
            self.stack.setCurrentIndex(0)
            self.class_combo.setCurrentIndex(max(0, list(CLASS_NAMES).index(t["class"])))
            self.person_seed.setValue(int(t.get("seed", 0)))
            allowed = self.engine.class_param_names(t["class"])
            values = dict(t)
            if "start_m" in t:
                values["start_x_m"], values["start_y_m"] = t["start_m"]
            for name, spin in self.class_params.items():
                spin.setValue(float(values[name]) if name in values else spin.minimum())
                spin.setEnabled(name in allowed)
        elif "waypoints" in t:
            self.stack.setCurrentIndex(1)
            self.waypoints.set_rows(t["waypoints"])
        else:
            self.stack.setCurrentIndex(2)
        self.fixed_rcs.setChecked("rcs_dbsm" in person)
        self.rcs.setValue(float(person.get("rcs_dbsm", -8.0)))
        self.rcs.setEnabled("rcs_dbsm" in person)
        try:
            kind = person_model_kind(person.get("model", "point"))
        except InputError:
            kind = "point"
        self.person_model.setCurrentIndex(list(PERSON_MODELS).index(kind))
        self.height.setValue(float(person.get("height_m", DEFAULT_HEIGHT_M)))
        self.height.setEnabled(kind == "walking")

    def _sync_person_buttons(self, n_persons: int) -> None:
        """Remove needs two persons; add stops at the limit."""
        self.remove_button.setEnabled(n_persons > 1)
        full = n_persons >= MAX_PERSONS
        for b in (self.add_class_button, self.add_wp_button):
            b.setEnabled(not full)
            b.setToolTip(f"a scene holds at most {MAX_PERSONS} persons" if full else "")
