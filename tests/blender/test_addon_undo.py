# SPDX-License-Identifier: GPL-3.0-or-later
"""Undo: every operator of the add-on has the UNDO option, and Blender's Undo, which runs in
the background too (the factory start-up has a window), takes an operator's change back.
Run through run_in_blender.py."""

import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

from conftest import DATA, make_candide_head  # noqa: E402

from mpeg4face_blender.scene import live_preview  # noqa: E402

JOY = DATA / "xface-fap" / "joy.fap"


def addon_operators():
    """The registered operator classes defined in the add-on's modules."""
    found, todo = [], [bpy.types.Operator]
    while todo:
        cls = todo.pop()
        todo.extend(cls.__subclasses__())
        if cls.__module__.startswith("mpeg4face_blender.") and cls.is_registered:
            found.append(cls)
    return found


def test_every_operator_supports_undo():
    classes = addon_operators()
    # The classes are exactly the operators under bpy.ops.mpeg4face: none is missed.
    assert sorted(c.bl_idname for c in classes) == sorted(
        f"mpeg4face.{name}" for name in dir(bpy.ops.mpeg4face))
    assert len(classes) >= 13
    for cls in classes:
        assert {"REGISTER", "UNDO"} <= cls.bl_options, cls.bl_idname


@pytest.fixture
def head():
    """The name of make_candide_head()'s object, with an undo step pushed after it. Undo
    reloads the data, so the test and the clean-up look the object up by name: references
    taken before an undo are stale."""
    obj, _, _ = make_candide_head()
    name = obj.name
    bpy.ops.ed.undo_push(message="mpeg4face test: the head")
    yield name
    obj = bpy.data.objects.get(name)
    if obj is not None:
        live_preview.stop_live(obj)
        mesh = obj.data
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)
    for action in list(bpy.data.actions):
        bpy.data.actions.remove(action)


def key_names(name):
    keys = bpy.data.objects[name].data.shape_keys
    return keys.key_blocks.keys() if keys is not None else []


def test_undo_and_redo_an_operator(head):
    """bpy.ops called with undo=True (a script's call pushes no step otherwise) pushes a step
    after an operator with the UNDO option: Undo takes exactly its key away, Redo brings it
    back. Without the option no step would follow it, and Undo would go past the head."""
    assert bpy.ops.mpeg4face.add_fap_shape_key(
        "EXEC_DEFAULT", True, fap="3", amplitude=512) == {"FINISHED"}
    assert key_names(head) == ["Basis", "fap3_open_jaw@512"]
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert key_names(head) == []
    assert bpy.ops.ed.redo() == {"FINISHED"}
    assert key_names(head) == ["Basis", "fap3_open_jaw@512"]


def test_undo_of_the_live_preview_ends_it(head):
    """Undo removes the live key the preview writes into; the next frame change ends the
    preview instead of writing into a key that is gone."""
    bpy.ops.mpeg4face.add_fap_shape_key(fap="3", amplitude=512)
    bpy.ops.ed.undo_push(message="mpeg4face test: the key")
    assert bpy.ops.mpeg4face.import_fap_stream(
        "EXEC_DEFAULT", True, filepath=str(JOY), preview="LIVE") == {"FINISHED"}
    assert live_preview.LIVE_KEY in key_names(head)
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert key_names(head) == ["Basis", "fap3_open_jaw@512"]
    assert not bpy.data.objects[head].show_only_shape_key
    bpy.context.scene.frame_set(3)  # must not raise
    assert not live_preview._live
    assert live_preview._on_frame_change not in bpy.app.handlers.frame_change_pre
