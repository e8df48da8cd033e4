# SPDX-License-Identifier: GPL-3.0-or-later
"""Find Feature Points and Make Animatable (docs/landmarks.md) on the MakeHuman sample's skin
with its feature points deleted, the ICT sample as template: the points come back near the
head's own, undoably, with the confidence per point; then the template's shape keys are
cloned on. Run through run_in_blender.py."""

import sys

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

from conftest import ROOT, makehuman_skin  # noqa: E402

from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.ui import preferences  # noqa: E402
from mpeg4face_blender.ui.operators.feature_points import CONFIDENCE  # noqa: E402

# Lip corners and contact points, outer lip mid points, eye corners, nose tip, subnasale.
NAMED = "8.3 8.4 2.2 2.3 8.1 8.2 3.7 3.11 3.8 3.12 9.3 9.15".split()


@pytest.fixture(scope="module")
def template(tmp_path_factory):
    """The ICT sample head (with its FAP, viseme and expression keys), built as samples/build.sh
    builds it."""
    out = tmp_path_factory.mktemp("ict")
    sys.path.insert(0, str(ROOT / "samples"))
    try:
        import ict_head
    finally:
        sys.path.remove(str(ROOT / "samples"))
    assert ict_head.main(["--out", str(out)]) == 0
    return str(out / "ict_head.glb")


@pytest.fixture
def head():
    """The MakeHuman skin without FP_ groups, active and selected, an undo step pushed after
    it; its own points (feature point -> vertex) kept to compare. Yields the object's name
    (undo reloads the data: references taken before it are stale)."""
    obj, truth = makehuman_skin()
    for group in list(obj.vertex_groups):
        obj.vertex_groups.remove(group)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    name = obj.name
    bpy.ops.ed.undo_push(message="mpeg4face test: the bare head")
    yield name, truth
    obj = bpy.data.objects.get(name)
    if obj is not None:
        mesh = obj.data
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)


def fp_vertices(name):
    obj = bpy.data.objects[name]
    groups = {g.index: feature_points.feature_point_of_group(g.name) for g in obj.vertex_groups}
    return {groups[g.group]: v.index for v in obj.data.vertices for g in v.groups
            if groups.get(g.group)}


def test_find_feature_points_places_the_heads_points_undoably(head, template):
    name, truth = head
    assert bpy.ops.mpeg4face.find_feature_points(
        "EXEC_DEFAULT", True, template=template) == {"FINISHED"}
    found = fp_vertices(name)
    # The ICT head's 85 less those on its eyes, teeth and tongue (a skin has none) and 7.1,
    # 7.2 inside the head: 73.
    assert len(found) == 73
    coords = feature_points.to_standard_axes(
        np.array([v.co for v in bpy.data.objects[name].data.vertices]))
    # Twice the inner eye corners' distance: about ES0 (the pupils are on the eyes, not here).
    es0 = np.linalg.norm(coords[truth["3.11"]] - coords[truth["3.8"]]) * 2
    errors = np.array([np.linalg.norm(coords[found[p]] - coords[truth[p]]) for p in NAMED])
    assert np.median(errors) / es0 < 0.06, errors / es0
    confidence = bpy.data.objects[name][CONFIDENCE]
    assert set(confidence.keys()) == set(found) and all(0 <= c <= 1 for c in confidence.values())
    # One step takes it all back.
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert fp_vertices(name) == {}


def test_make_animatable_finds_the_points_and_clones_the_keys(head, template):
    name, _ = head
    assert bpy.ops.mpeg4face.make_animatable(template=template) == {"FINISHED"}
    obj = bpy.data.objects[name]
    assert feature_points.cloning_points() <= set(fp_vertices(name))
    keys = obj.data.shape_keys.key_blocks.keys()
    assert sum(k.startswith("fap") for k in keys) > 100
    assert any(k.startswith("viseme") for k in keys)
    assert any(k.startswith("expression") for k in keys)


def test_without_a_template_it_says_where_to_set_one(head):
    assert preferences.preferences(bpy.context).template_head == ""
    with pytest.raises(RuntimeError, match="No template head"):
        bpy.ops.mpeg4face.find_feature_points()
