# SPDX-License-Identifier: GPL-3.0-or-later
"""Operators for FAP shape keys, FaceDefTables and cloning: add a key named in the grammar
of docs/fat.md, map keys named otherwise onto new grammar keys, mirror a FAP key onto its
left/right partner, generate the FaceDefTables and clone the keys onto other heads.

They only ever add keys (or, when cloning, overwrite keys of the same grammar name): the
Basis and the user's other keys are left as they are. Problems are reported, never raised.
"""

# No postponed annotations: bpy reads the property annotations.
from collections.abc import Callable, Mapping

import bpy
import numpy as np
from bpy.app.handlers import persistent
from bpy.props import BoolProperty, CollectionProperty, EnumProperty, FloatProperty, \
    IntProperty, StringProperty

import mpeg4face

from ...logic import feature_points, shape_keys
from ...scene import mesh_data, poses
from .. import text as ui_text
from .feature_points import TemplateHead, active_mesh, find_feature_points, read_template

# The last "Generate FaceDefTables" (or export) report per object name, for the panel;
# forgotten when another file is loaded.
table_reports: dict[str, shape_keys.TablesReport] = {}


@persistent
def _forget_table_reports(*_args: object) -> None:
    table_reports.clear()

_AMPLITUDE_LIMIT = 2**20  # far beyond any FAP's useful range; only keeps the field sane


# --- shape-key data -------------------------------------------------------------------------


def basis_coords(obj: bpy.types.Object) -> np.ndarray:
    """The Basis key's positions, or the mesh's when it has no shape keys."""
    keys = obj.data.shape_keys
    if keys is not None:
        return mesh_data.shape_key_coords(keys.reference_key)
    out = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.vertices.foreach_get("co", out)
    return out.reshape(-1, 3).astype(np.float64)


def add_key(obj: bpy.types.Object, name: str, coords: np.ndarray | None = None
            ) -> bpy.types.ShapeKey:
    """A new key relative to the Basis, a copy of the Basis (not of the mix, so the values
    of the other keys do not leak in) or `coords`, with the grammar's slider range, at
    value 0: the face stays at rest (Blender 5.0 adds a key at 1, which would pile every
    generated or cloned key onto the face)."""
    if obj.data.shape_keys is None:
        obj.shape_key_add(name="Basis", from_mix=False)
    key = obj.shape_key_add(name=name, from_mix=False)
    key.value = 0.0
    key.relative_key = obj.data.shape_keys.reference_key
    if coords is not None:
        mesh_data.set_shape_key_coords(key, coords)
    set_slider_range(key)
    return key


def set_slider_range(key: bpy.types.ShapeKey) -> None:
    low, high = shape_keys.slider_range(key.name)
    key.slider_max = high  # max first: Blender keeps min below max
    key.slider_min = low


def write_keys(obj: bpy.types.Object, displacements: Mapping[str, shape_keys.Displacement]
               ) -> int:
    """Grammar keys from displacements (Blender's axes; every vertex's, or a sparse shape's
    vertices and theirs: shape_keys.moved_coords) from the Basis: a key of that name
    is overwritten in place, keeping its drivers and animation, its slider range widened to
    the grammar's (never narrowed: a bake may have widened it); the others are added.
    Returns how many were replaced."""
    basis = basis_coords(obj)
    replaced = 0
    for name, displacement in displacements.items():
        keys = obj.data.shape_keys
        existing = keys.key_blocks.get(name) if keys is not None else None
        coords = shape_keys.moved_coords(basis, displacement)
        if existing is None:
            add_key(obj, name, coords)
            continue
        mesh_data.set_shape_key_coords(existing, coords)
        low, high = shape_keys.slider_range(name)
        existing.slider_max = max(existing.slider_max, high)
        existing.slider_min = min(existing.slider_min, low)
        replaced += 1
    return replaced


def key_names(obj: bpy.types.Object) -> list[str]:
    """Every shape key of the object but the Basis."""
    keys = obj.data.shape_keys
    if keys is None:
        return []
    return [k.name for k in keys.key_blocks if k != keys.reference_key]


def generate(obj: bpy.types.Object, threshold: float, scene: bpy.types.Scene,
             progress: Callable[[float], None] | None = None,
             absolute_threshold: float | None = None
             ) -> tuple[mpeg4face.MpegFace, shape_keys.TablesReport]:
    """generate_face on the object's keys, its parts' keys and the scene's pose markers
    with the rig's deformed copies there (poses.read_posed_face_model; progress(fraction)
    follows the markers): the face and its report (with the FP_ group warnings); raises
    mpeg4face.Error with the core's reason (e.g. "MNS0 is not measured: needs 9.15 and
    2.2") or the rig's (poses.RigError)."""
    model, group_warnings = poses.read_posed_face_model(obj, key_names, scene, progress)
    generated = mpeg4face.generate_face(model, threshold, absolute_threshold)
    return generated["face"], shape_keys.tables_report(generated, group_warnings)


# --- checks shared by the operators ---------------------------------------------------------


def editable_mesh(op: bpy.types.Operator, context: bpy.types.Context) -> bpy.types.Object | None:
    """The active mesh in Object Mode (in Edit Mode Blender would overwrite new keys with
    the edit mesh's on leaving it)."""
    obj = active_mesh(op, context)
    if obj is not None and obj.mode != "OBJECT":
        op.report({"ERROR"}, "Switch to Object Mode to change shape keys")
        return None
    return obj


def has_feature_points(op: bpy.types.Operator, obj: bpy.types.Object) -> bool:
    if any(feature_points.feature_point_of_group(g.name) for g in obj.vertex_groups):
        return True
    op.report({"ERROR"}, f"{obj.name} has no feature points (FP_ vertex groups): "
              "assign them in the Feature Points panel")
    return False


def has_keys(op: bpy.types.Operator, obj: bpy.types.Object,
             scene: bpy.types.Scene | None = None) -> bool:
    """Whether the object has shape keys besides the Basis (or, given the scene, pose
    markers), else an error report."""
    keys = obj.data.shape_keys
    if keys is not None and len(keys.key_blocks) > 1:
        return True
    if scene is not None and poses.pose_markers(scene, obj):
        return True
    op.report({"ERROR"}, f"{obj.name} has no shape keys besides the Basis"
              + (" and the scene no pose markers" if scene is not None else "")
              + ": add FAP shape keys")
    return False


def refuse_duplicate(op: bpy.types.Operator, obj: bpy.types.Object, name: str) -> bool:
    keys = obj.data.shape_keys
    if keys is not None and name in keys.key_blocks:
        op.report({"ERROR"}, f"{obj.name} already has a shape key {name}: pick another "
                  "amplitude or sculpt that key")
        return True
    return False


def with_progress(context: bpy.types.Context, steps: int, work: Callable[[Callable], object]):
    """Runs work(update) between progress_begin and progress_end; update(x) takes 0..steps."""
    wm = context.window_manager
    wm.progress_begin(0, steps)
    try:
        return work(wm.progress_update)
    finally:
        wm.progress_end()


# --- operators ------------------------------------------------------------------------------

_KIND_ITEMS = (
    ("FAP", "FAP", "A low-level FAP (3..68) at an amplitude in FAPU units"),
    ("VISEME", "Viseme", "A viseme (1..14), FAP 1"),
    ("EXPRESSION", "Expression", "An expression (1..6) at an intensity, FAP 2"),
)


class _KeyChoice:
    """The properties naming a grammar key, shared by Add and Map."""

    kind: EnumProperty(name="Kind", items=_KIND_ITEMS, default="FAP")
    fap: EnumProperty(name="FAP", items=shape_keys.fap_enum_items())
    viseme: EnumProperty(name="Viseme", items=shape_keys.viseme_enum_items())
    expression: EnumProperty(name="Expression", items=shape_keys.expression_enum_items())
    amplitude: IntProperty(
        name="Amplitude", description="The FAP value this key's shape shows, in FAPU units "
        "(1024 = one FAPU distance; negative for the opposite motion of a bidirectional FAP)",
        default=shape_keys.DEFAULT_AMPLITUDE, min=-_AMPLITUDE_LIMIT, max=_AMPLITUDE_LIMIT)
    intensity: IntProperty(name="Intensity", description="Expression intensity this key shows",
                           default=shape_keys.FULL_INTENSITY, min=1,
                           max=shape_keys.FULL_INTENSITY)

    def key_name(self) -> str:
        number = int({"FAP": self.fap, "VISEME": self.viseme,
                      "EXPRESSION": self.expression}[self.kind])
        return shape_keys.key_name(self.kind, number, self.amplitude, self.intensity)

    def draw_choice(self, layout: bpy.types.UILayout) -> None:
        layout.prop(self, "kind", expand=True)
        if self.kind == "FAP":
            layout.prop(self, "fap")
            layout.prop(self, "amplitude")
        elif self.kind == "VISEME":
            layout.prop(self, "viseme")
        else:
            layout.prop(self, "expression")
            layout.prop(self, "intensity")


class MPEG4FACE_OT_add_fap_shape_key(_KeyChoice, bpy.types.Operator):
    """Add a shape key for a FAP at an amplitude, a viseme or an expression, named in the
    grammar (fap3_open_jaw@1024), a copy of the Basis to sculpt"""

    bl_idname = "mpeg4face.add_fap_shape_key"
    bl_label = "Add FAP Shape Key"
    bl_options = {"REGISTER", "UNDO"}
    bl_property = "fap"  # what invoke_search_popup searches

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if self.kind == "FAP":
            context.window_manager.invoke_search_popup(self)
            return {"RUNNING_MODAL"}
        return context.window_manager.invoke_props_dialog(self)

    def draw(self, context: bpy.types.Context) -> None:
        self.draw_choice(self.layout)

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = editable_mesh(self, context)
        if obj is None:
            return {"CANCELLED"}
        if self.kind == "FAP" and self.amplitude == 0:
            self.report({"ERROR"}, "Amplitude 0 is the neutral face: pick another amplitude")
            return {"CANCELLED"}
        name = self.key_name()
        if refuse_duplicate(self, obj, name):
            return {"CANCELLED"}
        key = add_key(obj, name)
        obj.active_shape_key_index = list(obj.data.shape_keys.key_blocks).index(key)
        self.report({"INFO"}, f"Added shape key {name}: sculpt it in Edit Mode")
        return {"FINISHED"}


class MPEG4FACE_PG_key_mapping(_KeyChoice, bpy.types.PropertyGroup):
    key: StringProperty(name="Shape key")
    use: BoolProperty(name="Map", description="Create a grammar key from this key")


def fill_mappings(obj: bpy.types.Object, mappings) -> None:
    """One row per key that is neither the Basis nor named in the grammar, with the
    suggested FAP, viseme or expression (rows without a suggestion start unticked)."""
    mappings.clear()
    keys = obj.data.shape_keys
    for key in keys.key_blocks if keys is not None else ():
        if key == keys.reference_key or shape_keys.is_grammar_name(key.name):
            continue
        row = mappings.add()
        row.key = key.name
        suggestion = shape_keys.suggest(key.name)
        row.use = suggestion is not None
        if suggestion is not None:
            row.kind = suggestion.kind
            setattr(row, suggestion.kind.lower(), str(suggestion.number))


class MPEG4FACE_OT_map_shape_keys(bpy.types.Operator):
    """Create grammar-named copies of shape keys named otherwise (jawOpen -> a new key
    fap3_open_jaw@1024 with the same shape); the original keys stay as they are"""

    bl_idname = "mpeg4face.map_shape_keys"
    bl_label = "Map Shape Keys"
    bl_options = {"REGISTER", "UNDO"}

    mappings: CollectionProperty(type=MPEG4FACE_PG_key_mapping)

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        obj = editable_mesh(self, context)
        if obj is None or not has_keys(self, obj):
            return {"CANCELLED"}
        fill_mappings(obj, self.mappings)
        if not self.mappings:
            self.report({"INFO"}, "Every shape key is already named in the grammar")
            return {"CANCELLED"}
        return context.window_manager.invoke_props_dialog(self, width=700)

    def draw(self, context: bpy.types.Context) -> None:
        for row in self.mappings:
            line = self.layout.row()
            line.prop(row, "use", text=row.key)
            sub = line.row()
            sub.active = row.use
            sub.prop(row, "kind", text="")
            if row.kind == "FAP":
                sub.prop(row, "fap", text="")
                sub.prop(row, "amplitude")
            elif row.kind == "VISEME":
                sub.prop(row, "viseme", text="")
            else:
                sub.prop(row, "expression", text="")
                sub.prop(row, "intensity")

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = editable_mesh(self, context)
        if obj is None or not has_keys(self, obj):
            return {"CANCELLED"}
        if not self.mappings:  # run from a script without rows: take the suggestions
            fill_mappings(obj, self.mappings)
        blocks = obj.data.shape_keys.key_blocks
        created = []
        for row in self.mappings:
            if not row.use:
                continue
            source = blocks.get(row.key)
            if source is None:
                self.report({"WARNING"}, f"No shape key {row.key}")
                continue
            if row.kind == "FAP" and row.amplitude == 0:
                self.report({"WARNING"}, f"{row.key}: amplitude 0 is the neutral face, skipped")
                continue
            name = row.key_name()
            if name in blocks:
                self.report({"WARNING"}, f"{row.key}: {name} exists already, skipped")
                continue
            add_key(obj, name, mesh_data.shape_key_coords(source))
            created.append(f"{row.key} -> {name}")
        if not created:
            self.report({"WARNING"}, "No shape key mapped")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Mapped {len(created)} shape keys: {'; '.join(created)}")
        return {"FINISHED"}


class MPEG4FACE_OT_mirror_shape_key(bpy.types.Operator):
    """Create the left/right partner of the active FAP shape key (fap6 stretch_l_cornerlip
    -> fap7 stretch_r_cornerlip): each vertex moves as its mirror vertex does, mirrored,
    across the plane of symmetry of the left/right feature points (X = 0 without them)"""

    bl_idname = "mpeg4face.mirror_shape_key"
    bl_label = "Mirror Shape Key"
    bl_options = {"REGISTER", "UNDO"}

    tolerance: FloatProperty(
        name="Tolerance",
        description="A vertex without another vertex this near (a fraction of the mesh's "
        "bounding-box diagonal) to its mirror image does not move",
        default=0.001, min=0.0, max=1.0, subtype="FACTOR", precision=4)

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = editable_mesh(self, context)
        if obj is None or not has_keys(self, obj):
            return {"CANCELLED"}
        key = obj.active_shape_key
        try:
            mirrored = shape_keys.mirrored_key(key.name)
        except ValueError as error:
            self.report({"ERROR"}, f"Active shape key: {error}")
            return {"CANCELLED"}
        if refuse_duplicate(self, obj, mirrored.name):
            return {"CANCELLED"}
        basis = basis_coords(obj)
        with mesh_data.face_bmesh(obj) as bm:
            fp_vertices, _ = feature_points.fp_vertices_from_groups(mesh_data.fp_groups(obj, bm))
        plane = shape_keys.symmetry_plane(basis, fp_vertices)
        partners = shape_keys.mirror_vertices(
            basis, feature_points.mirror_tolerance(basis, self.tolerance), plane)
        displacement = shape_keys.mirror_displacements(
            mesh_data.shape_key_coords(key) - basis, partners, plane)
        add_key(obj, mirrored.name, basis + displacement)
        unmatched = np.flatnonzero(partners < 0)
        if len(unmatched):
            listed = ", ".join(map(str, unmatched[:20])) + (" ..." if len(unmatched) > 20 else "")
            self.report({"WARNING"}, f"{len(unmatched)} vertices have no mirror vertex and "
                        f"do not move: {listed}")
        across = (f"the plane of {plane.pairs} left/right feature point pairs" if plane.pairs
                  else "X = 0 (no left/right feature point pair is set)")
        self.report({"INFO"}, f"Mirrored {key.name} to {mirrored.name} across {across}")
        return {"FINISHED"}


class MPEG4FACE_OT_generate_tables(bpy.types.Operator):
    """Generate the FaceDefTables from the active mesh's FAP shape keys and report the FAPs
    covered, the vertices each table moves, warnings and the keys ignored"""

    bl_idname = "mpeg4face.generate_tables"
    bl_label = "Generate FaceDefTables"
    bl_options = {"REGISTER", "UNDO"}

    threshold: FloatProperty(
        name="Threshold", description="FAPU a vertex must move to be in a table",
        default=0.01, min=0.0, soft_max=1.0)
    # The core's message for a face without FAPU asks for this threshold.
    absolute_threshold: FloatProperty(
        name="Absolute threshold", description="Instead of the FAPU one: the distance (in "
        "the mesh's units) a vertex must move to be in a table; 0 counts it in FAPU, which "
        "needs the FAPU measured", default=0.0, min=0.0, soft_max=1.0, precision=5)

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = active_mesh(self, context)
        if obj is None or not has_keys(self, obj, context.scene) \
                or not has_feature_points(self, obj):
            return {"CANCELLED"}
        if obj.mode == "EDIT":
            obj.update_from_editmode()  # the keys' data is stale in Edit Mode
        try:
            _, report = with_progress(context, 1, lambda update: generate(
                obj, self.threshold, context.scene, update, self.absolute_threshold or None))
        except mpeg4face.Error as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        table_reports[obj.name] = report
        lines = report.lines()
        for line in lines[1:]:
            self.report({"WARNING"} if line.startswith(("warning", "ignored")) else {"INFO"},
                        line)
        self.report({"INFO"}, lines[0])
        if any(line.startswith(("warning", "ignored")) for line in lines):
            ui_text.popup(context, "FaceDefTables", lines, icon="ERROR")
        return {"FINISHED"}


class MPEG4FACE_OT_clone_motion(bpy.types.Operator):
    """Clone the active mesh's FAP shape keys onto the other selected meshes (each with its
    FP_ feature points): one shape key per cloned key"""

    bl_idname = "mpeg4face.clone_motion"
    bl_label = "Clone Facial Motion"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context: bpy.types.Context) -> set[str]:
        source = editable_mesh(self, context)
        if source is None or not has_keys(self, source, context.scene) \
                or not has_feature_points(self, source):
            return {"CANCELLED"}
        targets = [o for o in context.selected_objects if o != source and o.type == "MESH"]
        if not targets:
            self.report({"ERROR"}, "Select the target meshes, then the source head last "
                        "(active)")
            return {"CANCELLED"}
        try:  # the head's keys and its rig's deformed copies at the pose markers
            source_model, _ = poses.head_model(source, key_names, context.scene)
        except mpeg4face.Error as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}

        def work(update: Callable[[float], None]) -> int:
            done = 0
            for i, target in enumerate(targets):
                if not has_feature_points(self, target):  # reported; the others go on
                    continue
                target_model, _ = mesh_data.read_face_model(target)
                try:
                    cloned = mpeg4face.clone_face(
                        source_model, target_model,
                        progress=lambda _stage, fraction, i=i: update(i + fraction))
                except mpeg4face.Error as error:
                    self.report({"ERROR"}, f"{target.name}: {error}")
                    continue
                self.report_target(target, cloned)
                done += 1
            return done

        if not with_progress(context, len(targets), work):
            return {"CANCELLED"}
        return {"FINISHED"}

    def report_target(self, target: bpy.types.Object, cloned: dict) -> None:
        """Writes the cloned keys: a key of the same (grammar) name is overwritten in place,
        keeping its drivers and animation; every other key stays."""
        replaced = write_keys(target, shape_keys.cloned_shapes(cloned["copies"]))
        for warning in cloned["warnings"]:
            self.report({"WARNING"}, f"{target.name}: {warning}")
        self.report({"INFO"}, f"{target.name}: {len(cloned['copies'])} shape keys cloned "
                    f"({replaced} replaced)")


class MPEG4FACE_OT_make_animatable(TemplateHead, bpy.types.Operator):
    """Make the active head animatable in one step: its feature points found from the
    template head (unless it has those cloning needs), then the template's FAP, viseme and
    expression shape keys cloned onto it, ready for Generate FaceDefTables"""

    bl_idname = "mpeg4face.make_animatable"
    bl_label = "Make Animatable"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = editable_mesh(self, context)
        if obj is None:
            return {"CANCELLED"}
        template = read_template(self, context, self.template)
        if template is None:
            return {"CANCELLED"}

        def work(update: Callable[[float], None]) -> bool:
            _, _, fp_vertices, _ = mesh_data.mesh_and_points(obj)
            if not feature_points.cloning_points() <= set(fp_vertices):
                if not find_feature_points(self, obj, template, update):
                    return False
            target, _ = mesh_data.read_face_model(obj)
            try:
                cloned = mpeg4face.clone_face(
                    template, target, relaxation=mpeg4face.CloneRelaxation(),
                    progress=lambda _stage, fraction: update(1 + fraction))
            except mpeg4face.Error as error:
                self.report({"ERROR"}, f"{obj.name}: {error}")
                return False
            replaced = write_keys(obj, shape_keys.cloned_shapes(cloned["copies"]))
            self.report({"INFO"}, f"{obj.name}: {len(cloned['copies'])} shape keys cloned "
                        f"({replaced} replaced); next, Generate FaceDefTables")
            return True

        return {"FINISHED"} if with_progress(context, 2, work) else {"CANCELLED"}


_classes = (
    MPEG4FACE_OT_add_fap_shape_key,
    MPEG4FACE_PG_key_mapping,
    MPEG4FACE_OT_map_shape_keys,
    MPEG4FACE_OT_mirror_shape_key,
    MPEG4FACE_OT_generate_tables,
    MPEG4FACE_OT_clone_motion,
    MPEG4FACE_OT_make_animatable,
)


def register() -> None:
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.app.handlers.load_post.append(_forget_table_reports)


def unregister() -> None:
    if _forget_table_reports in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_forget_table_reports)
    table_reports.clear()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
