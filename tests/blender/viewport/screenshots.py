# SPDX-License-Identifier: GPL-3.0-or-later
"""The real viewport, under a virtual display: CANDIDE-3 with a FAP 3 (open_jaw) shape key
and its feature points, the add-on's sidebar open, joy.fap imported, baked and
encoded, the FaceDefTables generated. Screenshots of the neutral frame and of the frame
where the jaw is most open, and of the whole window twice: the feature point panels
(blender_sidebar.png), then the shape key, FaceDefTables, cloning and FAP stream panels
(blender_sidebar_keys.png); then how much the mouth region and the forehead changed between
the two frames, measured on the screenshots. Written to $MPEG4FACE_SCREENSHOT_DIR (PNGs and
result.json).

    xvfb-run -s "-screen 0 1600x1000x24" blender --factory-startup --enable-event-simulate \\
        --python tests/blender/viewport/screenshots.py

run by test_viewport.py. Needs MPEG4FACE_PYTHONPATH (the build's python folder), like
run_in_blender.py. Exits 0 when it wrote result.json, else 1 (with the error printed).
"""

import json
import os
import sys
import tempfile
import traceback
from pathlib import Path

import bpy

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent.parent
OUT = Path(os.environ["MPEG4FACE_SCREENSHOT_DIR"])
sys.path[:0] = [os.environ["MPEG4FACE_PYTHONPATH"], str(ROOT / "blender_addon"), str(HERE.parent)]
if "/usr/lib/python3/dist-packages" not in sys.path:
    sys.path.append("/usr/lib/python3/dist-packages")  # numpy, pytest (conftest imports it)

import numpy as np  # noqa: E402
from bpy_extras.view3d_utils import location_3d_to_region_2d  # noqa: E402
from conftest import ADDON, DATA, make_candide_head  # noqa: E402

import addon_utils  # noqa: E402
import mpeg4face  # noqa: E402

KEY_AMPLITUDE = 315  # joy.fap's largest FAP 3
MOUTH = ("2.2", "2.3", "8.1", "8.2", "8.3", "8.4", "2.1")
FOREHEAD = ("11.1", "4.1", "4.2", "4.3", "4.4")


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = max((a for a in window.screen.areas if a.type == "VIEW_3D"),
               key=lambda a: a.width * a.height)
    region = next(r for r in area.regions if r.type == "WINDOW")
    return window, area, region


def show_only_our_sidebar_tab():
    """Blender 3.4 cannot choose a sidebar tab from Python: the other tabs' Python panels go
    (in this throw-away session), leaving Item (defined in C) and MPEG-4; steps() then clicks
    down the tab strip, as a user does, until our panel draws."""
    def subclasses(cls):
        for sub in cls.__subclasses__():
            yield from subclasses(sub)
            yield sub

    for panel in list(subclasses(bpy.types.Panel)):
        if (getattr(panel, "bl_space_type", "") == "VIEW_3D"
                and getattr(panel, "bl_region_type", "") == "UI"
                and getattr(panel, "bl_category", "") != "MPEG-4"
                and getattr(panel, "is_registered", False)):
            bpy.utils.unregister_class(panel)


def open_every_panel():
    """The sub-panels (closed by default) registered open, before they are first drawn, so
    that the screenshots show them."""
    from mpeg4face_blender.ui.panels import faces as panels_faces
    from mpeg4face_blender.ui.panels import feature_points as panels

    for panel in (panels.MPEG4FACE_PT_fapu, panels.MPEG4FACE_PT_location_warnings,
                  panels_faces.MPEG4FACE_PT_face_tables, panels_faces.MPEG4FACE_PT_cloning):
        bpy.utils.unregister_class(panel)
        panel.bl_options = panel.bl_options - {"DEFAULT_CLOSED"}
        bpy.utils.register_class(panel)


def our_panels():
    def subclasses(cls):
        for sub in cls.__subclasses__():
            yield from subclasses(sub)
            yield sub

    return [p for p in subclasses(bpy.types.Panel)
            if getattr(p, "bl_category", "") == "MPEG-4" and p.is_registered]


def cut_in_the_sidebar():
    """layout_check on every panel of the tab in the real sidebar (its width, the UI's
    scale), the feature point list's rows too: {panel: [cut texts]} and the width."""
    import layout_check
    from mpeg4face_blender.ui.panels import feature_points as panels

    window, area, region = view3d()
    sidebar = next(r for r in area.regions if r.type == "UI")
    with bpy.context.temp_override(window=window, area=area, region=sidebar):
        context = bpy.context
        cut = {p.__name__: layout_check.cut_labels(p, context, sidebar.width)
               for p in our_panels()}
        cut["feature point list"] = layout_check.cut_list_rows(
            panels.MPEG4FACE_UL_feature_points, context, sidebar.width,
            context.window_manager, "mpeg4face_feature_points")
    return {k: v for k, v in cut.items() if v}, sidebar.width


def sidebar_picture(window_png, name):
    """The sidebar cut out of a window screenshot, for the user guide."""
    window, area, _ = view3d()
    sidebar = next(r for r in area.regions if r.type == "UI")
    image = bpy.data.images.load(str(window_png))
    width, height = image.size
    rgba = np.array(image.pixels[:], dtype=np.float32).reshape(height, width, 4)
    bpy.data.images.remove(image)
    # window coordinates: the screenshot is the window, rows bottom-up
    x0, y0 = sidebar.x, sidebar.y  # window-relative, as the screenshot
    crop = rgba[y0:y0 + sidebar.height, x0:x0 + sidebar.width]
    out = bpy.data.images.new(name, crop.shape[1], crop.shape[0], alpha=True)
    out.pixels.foreach_set(crop.ravel())
    out.filepath_raw = str(OUT / name)
    out.file_format = "PNG"
    out.save()
    bpy.data.images.remove(out)


def set_up():
    """The head, its key, its tables, the stream baked and encoded, a clone target, the view
    from the front, the sidebar's tab."""
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    addon_utils.enable(ADDON, default_set=True)
    open_every_panel()
    obj, model, _ = make_candide_head()
    jaw = next(t for t in model.meshes[0].morph_targets if t.name.startswith("FAP 3 "))
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name=f"fap3_open_jaw@{KEY_AMPLITUDE}", from_mix=False)
    co = np.empty(len(key.data) * 3, dtype=np.float32)
    key.data.foreach_get("co", co)
    drop = jaw.displacements * 0.15  # the unit's full motion is half the head's height
    co += np.column_stack((drop[:, 0], -drop[:, 2], drop[:, 1])).astype(np.float32).ravel()
    key.data.foreach_set("co", co)
    result = bpy.ops.mpeg4face.import_fap_stream(filepath=str(DATA / "xface-fap" / "joy.fap"))
    assert result == {"FINISHED"}, result
    assert bpy.ops.mpeg4face.generate_tables() == {"FINISHED"}
    coded = Path(tempfile.mkdtemp()) / "joy_coded.fba"
    assert bpy.ops.mpeg4face.encode_fap_stream(filepath=str(coded), mode="dct") == {"FINISHED"}

    window, area, region = view3d()
    space = area.spaces.active
    space.show_region_ui = True
    space.shading.type = "SOLID"
    space.overlay.show_floor = False
    space.overlay.show_axis_x = space.overlay.show_axis_y = False
    show_only_our_sidebar_tab()
    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.ops.view3d.view_axis(type="FRONT")
        bpy.ops.view3d.view_selected()
    return obj


def screenshot(name):
    window, area, _ = view3d()
    path = OUT / name
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.screen.screenshot_area(filepath=str(path))
    return path


def pixels(path):
    image = bpy.data.images.load(str(path))
    width, height = image.size
    rgba = np.array(image.pixels[:], dtype=np.float32).reshape(height, width, 4)
    bpy.data.images.remove(image)
    return rgba[:, :, :3]  # rows bottom-up, as region coordinates


def box(obj, points):
    """The area-image pixel box around feature points (their vertices at the neutral frame),
    padded by a few pixels."""
    _, area, region = view3d()
    rv3d = area.spaces.active.region_3d
    xy = []
    for fp in points:
        group = obj.vertex_groups.get(f"FP_{fp}")
        vertex = next(v for v in obj.data.vertices if group.index in [g.group for g in v.groups])
        p = location_3d_to_region_2d(region, rv3d, obj.matrix_world @ vertex.co)
        xy.append((p.x + region.x - area.x, p.y + region.y - area.y))
    xy = np.array(xy)
    lo, hi = xy.min(axis=0) - 6, xy.max(axis=0) + 6
    return int(lo[0]), int(hi[0]), int(lo[1]), int(hi[1])


def change(a, b, where):
    x0, x1, y0, y1 = where
    return float(np.abs(a[y0:y1, x0:x1] - b[y0:y1, x0:x1]).mean())


def simulate(**event):
    window, _, _ = view3d()
    window.event_simulate(**event)


def show_shape_key_panels(obj):
    """The second page: the feature point panels go (in this throw-away session), leaving
    FAP Shape Keys, FaceDefTables, Cloning and FAP Stream; a second head, selected with the
    first one active, is the cloning target the Cloning panel names."""
    from mpeg4face_blender.ui.panels import feature_points as panels

    for panel in (panels.MPEG4FACE_PT_location_warnings, panels.MPEG4FACE_PT_fapu,
                  panels.MPEG4FACE_PT_feature_points):
        bpy.utils.unregister_class(panel)
    target = obj.copy()
    target.data = obj.data.copy()
    target.name = "target_head"
    target.location.x = obj.dimensions.x * 1.2
    bpy.context.scene.collection.objects.link(target)
    target.select_set(True)
    bpy.context.view_layer.objects.active = obj


def file_browser_screenshot(operator, name, filepath, panels=(), path_given=True):
    """The operator's file browser, as the File menu opens it, with its options, showing
    `filepath`; closed again afterwards. Returns the labels of `panels` (options
    sub-panels) that drew. path_given=False: the browser is opened without a path and then
    sent to filepath, for the imports, whose invoke() with a path given (a file dropped on
    the viewport) asks for the options in a dialog instead of opening the browser."""
    drawn = set()
    originals = {panel: panel.draw for panel in panels}

    def noting(draw):
        def noting_draw(self, context):
            drawn.add(self.bl_label)
            draw(self, context)
        return noting_draw

    for panel, draw in originals.items():
        panel.draw = noting(draw)
    windows = set(bpy.context.window_manager.windows[:])
    window, area, region = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region):
        if path_given:
            operator("INVOKE_DEFAULT", filepath=str(filepath))
        else:
            operator("INVOKE_DEFAULT")
    for _ in range(4):  # the window opens, then lists the folder
        yield
    browser = next(w for w in bpy.context.window_manager.windows if w not in windows)
    if not path_given:
        space = next(a for a in browser.screen.areas if a.type == "FILE_BROWSER").spaces[0]
        space.params.directory = str(filepath.parent).encode()
        space.params.filename = filepath.name
        for _ in range(2):  # the folder listed again, the file name shown
            yield
    with bpy.context.temp_override(window=browser):
        bpy.ops.screen.screenshot(filepath=str(OUT / name))
    for panel, draw in originals.items():
        panel.draw = draw
    area = next(a for a in browser.screen.areas if a.type == "FILE_BROWSER")
    with bpy.context.temp_override(window=browser, area=area):
        bpy.ops.file.cancel()
    yield
    return sorted(drawn)


def steps():
    simulate(type="ESC", value="PRESS")  # the splash screen
    yield
    obj = set_up()
    yield
    _, area, _ = view3d()
    sidebar = next(r for r in area.regions if r.type == "UI")
    from mpeg4face_blender.ui.panels import feature_points as panels

    drawn = []
    draw = panels.MPEG4FACE_PT_feature_points.draw

    def noting_draw(self, context):
        drawn.append(True)
        draw(self, context)

    panels.MPEG4FACE_PT_feature_points.draw = noting_draw
    tab_x = sidebar.x + sidebar.width - 8
    for below_top in range(20, 400, 12):
        if drawn:
            break
        y = sidebar.y + sidebar.height - below_top
        simulate(type="MOUSEMOVE", value="NOTHING", x=tab_x, y=y)
        simulate(type="LEFTMOUSE", value="PRESS", x=tab_x, y=y)
        simulate(type="LEFTMOUSE", value="RELEASE", x=tab_x, y=y)
        yield
    panels.MPEG4FACE_PT_feature_points.draw = draw
    assert drawn, "the MPEG-4 tab could not be opened"
    scene = bpy.context.scene
    values = mpeg4face.read_fap(DATA / "xface-fap" / "joy.fap").resolved()["values"][:, 2]
    neutral_frame = scene.frame_start + int(np.argmin(np.abs(values)))
    open_frame = scene.frame_start + int(np.argmax(values))
    scene.frame_set(neutral_frame)
    yield
    mouth, forehead = box(obj, MOUTH), box(obj, FOREHEAD)
    neutral = screenshot("viewport_neutral.png")
    window, _, _ = view3d()
    with bpy.context.temp_override(window=window):
        bpy.ops.screen.screenshot(filepath=str(OUT / "blender_sidebar.png"))
    sidebar_picture(OUT / "blender_sidebar.png", "blender_sidebar_229.png")
    cut, sidebar_width = cut_in_the_sidebar()
    scene.frame_set(open_frame)
    yield
    opened = screenshot("viewport_open_jaw.png")
    # The live preview, drawn with the gpu module over the hidden head (and the view
    # without the head, to tell that something is drawn there).
    obj.hide_set(True)
    yield
    empty = screenshot("viewport_empty.png")
    obj.hide_set(False)
    window, area, region = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region):
        assert bpy.ops.mpeg4face.live_preview(action="START") == {"FINISHED"}
    scene.frame_set(neutral_frame)
    yield
    live_neutral = screenshot("viewport_live_neutral.png")
    scene.frame_set(open_frame)
    yield
    live_opened = screenshot("viewport_live_open_jaw.png")
    live_hidden = len(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.vertices) == 0
    with bpy.context.temp_override(window=window, area=area, region=region):
        assert bpy.ops.mpeg4face.live_preview(action="STOP") == {"FINISHED"}
    show_shape_key_panels(obj)
    yield
    with bpy.context.temp_override(window=window):
        bpy.ops.screen.screenshot(filepath=str(OUT / "blender_sidebar_keys.png"))
    sidebar_picture(OUT / "blender_sidebar_keys.png", "blender_sidebar_keys_229.png")
    cut_keys, _ = cut_in_the_sidebar()
    cut.update(cut_keys)
    from mpeg4face_blender.ui.operators import export

    export_panels = yield from file_browser_screenshot(
        bpy.ops.mpeg4face.export_vrml, "blender_export.png",
        Path(tempfile.mkdtemp()) / "candide3.wrl",
        (export.MPEG4FACE_PT_export_head, export.MPEG4FACE_PT_export_tables))
    yield from file_browser_screenshot(bpy.ops.mpeg4face.import_fap_stream, "blender_import.png",
                                       DATA / "xface-fap" / "joy.fap", path_given=False)
    yield from file_browser_screenshot(
        bpy.ops.mpeg4face.import_livelink_capture, "blender_import_capture.png",
        DATA / "livelink-face" / "MySlate_3_Jason_Millers_iPhone.csv", path_given=False)
    a, b = pixels(neutral), pixels(opened)
    live_a, live_b = pixels(live_neutral), pixels(live_opened)
    result = {
        "neutral_frame": neutral_frame,
        "open_jaw_frame": open_frame,
        "open_jaw_value": int(values.max()),
        "key_value": obj.data.shape_keys.key_blocks[1].value,
        "mouth_box": mouth,
        "forehead_box": forehead,
        "mouth_change": change(a, b, mouth),
        "forehead_change": change(a, b, forehead),
        "live_mouth_change": change(live_a, live_b, mouth),
        "live_forehead_change": change(live_a, live_b, forehead),
        "live_hidden": live_hidden,
        # the drawn face where the solid one was: both differ from the empty background
        "live_face_drawn": change(live_a, pixels(empty), forehead),
        "image_size": list(a.shape[:2]),
        "export_panels": export_panels,
        "sidebar_width": sidebar_width,
        "cut": cut,
    }
    (OUT / "result.json").write_text(json.dumps(result, indent=1))


def main():
    runner = steps()

    def tick():
        try:
            next(runner)
            return 0.5  # let the viewport redraw before the next step
        except StopIteration:
            code = 0
        except Exception:  # noqa: BLE001 - reported, then Blender exits non-zero
            traceback.print_exc()
            code = 1
        sys.stdout.flush()
        os._exit(code)  # quit without saving or asking

    bpy.app.timers.register(tick, first_interval=1.0)


main()
