# SPDX-License-Identifier: GPL-3.0-or-later
"""Enables the add-on (blender_addon/ is on sys.path, see run_in_blender.py) before any test
module imports it, so addon_utils owns the module, and builds the CANDIDE-3 head."""

from pathlib import Path

import pytest

try:
    import addon_utils
    import bpy
except ImportError:  # plain Python: the tests skip themselves
    bpy = None

ADDON = "mpeg4face_blender"
DATA = Path(__file__).resolve().parent.parent / "data"

if bpy is not None:
    addon_utils.enable(ADDON, default_set=True)

# Blender as a Python module (PyPI's bpy) runs in the background only and has no executable
# (bpy.app.binary_path is ""): tests that start a Blender of their own, or need a window,
# run in a Blender application only.
def needs_blender_executable(why: str = ""):
    """Skips the test (a mark) where Blender is a Python module: the reason says so, and
    why the test needs the executable."""
    return pytest.mark.skipif(
        bpy is None or not bpy.app.binary_path,
        reason=f"needs the blender executable{why} (bpy as a module has none)")


@pytest.fixture
def addon_disabled():
    """The add-on disabled for the test, enabled again afterwards."""
    addon_utils.disable(ADDON, default_set=True)
    yield
    addon_utils.enable(ADDON, default_set=True)


def standard_to_blender(coords):
    """The standard's Y-up coordinates as Blender's Z-up ones: (x, y, z) -> (x, -z, y)."""
    return [(x, -z, y) for x, y, z in coords]


def make_candide_head():
    """CANDIDE-3 as the active, selected Blender mesh object in Object Mode, its feature
    points from feature_points.csv as FP_ vertex groups: (object, FaceModel, feature point ->
    vertex). Also used by viewport/screenshots.py."""
    import mpeg4face

    model = mpeg4face.read_model(DATA / "candide3" / "candide3.wfm")
    points, _ = mpeg4face.read_feature_point_csv(DATA / "candide3" / "feature_points.csv", model)
    model.feature_points = points
    mesh = model.meshes[0]
    data = bpy.data.meshes.new("candide3")
    data.from_pydata(standard_to_blender(mesh.coord.tolist()), [], mesh.triangles().tolist())
    obj = bpy.data.objects.new("candide3", data)
    bpy.context.scene.collection.objects.link(obj)
    fp_vertices = {fp: b.vertex for fp, b in points.items()}
    for fp, vertex in fp_vertices.items():
        obj.vertex_groups.new(name=f"FP_{fp}").add([vertex], 1.0, "REPLACE")
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj, model, fp_vertices


@pytest.fixture
def candide_head():
    """make_candide_head(), removed afterwards."""
    obj, model, fp_vertices = make_candide_head()
    data = obj.data
    yield obj, model, fp_vertices
    if obj.mode != "OBJECT":
        bpy.ops.object.mode_set(mode="OBJECT")
    bpy.data.objects.remove(obj)
    bpy.data.meshes.remove(data)


def group_members(obj, name):
    """(vertex, weight) of a vertex group, read in Object Mode."""
    if obj.mode != "OBJECT":
        bpy.ops.object.mode_set(mode="OBJECT")
    group = obj.vertex_groups.get(name)
    if group is None:
        return None
    return [(v.index, g.weight) for v in obj.data.vertices for g in v.groups
            if g.group == group.index]


# A few ARKit blendshapes on CANDIDE-3 in three spellings (standard axes: Y up, +X the
# face's left): jawOpen drops everything below the mouth and the inner lower lip,
# eyeBlink_L closes the left upper lid onto the lower, MouthSmileLeft raises the left lip
# corner outwards. Pure numpy, shared with tests/python/test_blender_arkit_logic.py.
ARKIT_KEYS = ("jawOpen", "eyeBlink_L", "MouthSmileLeft")


def candide_arkit_shapes(coords, fp_vertices):
    """ARKit key name -> (N, 3) displacements (standard axes) on CANDIDE-3."""
    import numpy as np

    coords = np.asarray(coords, dtype=np.float64)
    shapes = {name: np.zeros_like(coords) for name in ARKIT_KEYS}
    below = coords[:, 1] < coords[fp_vertices["8.3"], 1] - 0.01
    shapes["jawOpen"][below] = (0.0, -0.1, 0.0)
    shapes["jawOpen"][fp_vertices["2.3"]] = (0.0, -0.1, 0.0)
    shapes["eyeBlink_L"][fp_vertices["3.1"]] = (0.0, -0.08, 0.0)
    shapes["MouthSmileLeft"][fp_vertices["8.3"]] = (0.03, 0.05, 0.0)
    return shapes
