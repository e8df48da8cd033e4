# SPDX-License-Identifier: GPL-3.0-or-later
"""Find Feature Points and Make Animatable (docs/landmarks.md) on each sample's skin with its
feature points deleted, the other sample as template: the points come back near the head's
own, undoably, with the confidence per point; then (MakeHuman) the ICT sample's shape keys
are cloned on. Run through run_in_blender.py."""

import sys
from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402

from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.ui import preferences  # noqa: E402
from mpeg4face_blender.ui.operators.feature_points import CONFIDENCE  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
# Lip corners and contact points, outer lip mid points, eye corners, nose tip, subnasale.
NAMED = "8.3 8.4 2.2 2.3 8.1 8.2 3.7 3.11 3.8 3.12 9.3 9.15".split()


def sample_modules():
    sys.path.insert(0, str(ROOT / "samples"))
    try:
        import build_samples
        import ict_head
    finally:
        sys.path.remove(str(ROOT / "samples"))
    return build_samples, ict_head


@pytest.fixture(scope="module")
def templates(tmp_path_factory):
    """The ICT sample head (with its FAP, viseme and expression keys, as samples/build.sh
    builds it) and the MakeHuman head with its points, as .glb files."""
    build_samples, ict_head = sample_modules()
    out = tmp_path_factory.mktemp("templates")
    assert ict_head.main(["--out", str(out)]) == 0
    mpeg4face.write_gltf(build_samples.makehuman_neutral(), out / "makehuman_head.glb")
    return {"ICT": str(out / "ict_head.glb"), "MakeHuman": str(out / "makehuman_head.glb")}


def skin_object(model, name):
    """The model's skin (mesh 0) as a Blender mesh object without FP_ groups, active and
    selected; and its own points (feature point -> vertex)."""
    skin, world = model.meshes[0], model.mesh_world_matrices()[0]
    data = bpy.data.meshes.new(name)
    data.from_pydata(feature_points.to_blender_axes(
        skin.coord @ world[:3, :3].T + world[:3, 3]).tolist(), [], skin.triangles().tolist())
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj, {fp: b.vertex for fp, b in model.feature_points.items() if b.mesh == 0}


def bare_head(kind, templates):
    """A sample's skin without its points and the other sample as template: yields (object
    name, its own points, the template's path, how many template points are on its skin).
    An undo step is pushed after it (undo reloads the data: references taken before are
    stale)."""
    build_samples, ict_head = sample_modules()
    model = build_samples.makehuman_neutral() if kind == "MakeHuman" \
        else ict_head.build(with_keys=False)[0]
    obj, truth = skin_object(model, kind)
    other = templates["ICT" if kind == "MakeHuman" else "MakeHuman"]
    on_skin = sum(b.mesh == 0 for b in mpeg4face.read_gltf(other).feature_points.values())
    name = obj.name
    bpy.ops.ed.undo_push(message="mpeg4face test: the bare head")
    yield name, truth, other, on_skin
    obj = bpy.data.objects.get(name)
    if obj is not None:
        mesh = obj.data
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)


@pytest.fixture(params=["MakeHuman", "ICT"])
def head(request, templates):
    yield from bare_head(request.param, templates)


@pytest.fixture
def makehuman(templates):
    yield from bare_head("MakeHuman", templates)


def fp_vertices(name):
    obj = bpy.data.objects[name]
    groups = {g.index: feature_points.feature_point_of_group(g.name) for g in obj.vertex_groups}
    return {groups[g.group]: v.index for v in obj.data.vertices for g in v.groups
            if groups.get(g.group)}


def test_find_feature_points_places_the_heads_points_undoably(head):
    name, truth, template, on_skin = head
    assert bpy.ops.mpeg4face.find_feature_points(
        "EXEC_DEFAULT", True, template=template) == {"FINISHED"}
    found = fp_vertices(name)
    # The template's points on its skin: not those on its eyes, teeth and tongue (a skin has
    # none), nor 7.1, 7.2 inside the head.
    assert len(found) == on_skin
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


def test_make_animatable_finds_the_points_and_clones_the_keys(makehuman, templates):
    name = makehuman[0]
    assert bpy.ops.mpeg4face.make_animatable(template=templates["ICT"]) == {"FINISHED"}
    obj = bpy.data.objects[name]
    assert feature_points.cloning_points() <= set(fp_vertices(name))
    keys = obj.data.shape_keys.key_blocks.keys()
    assert sum(k.startswith("fap") for k in keys) > 100
    assert any(k.startswith("viseme") for k in keys)
    assert any(k.startswith("expression") for k in keys)


def test_without_a_template_it_says_where_to_set_one(makehuman):
    assert preferences.preferences(bpy.context).template_head == ""
    with pytest.raises(RuntimeError, match="No template head"):
        bpy.ops.mpeg4face.find_feature_points()
