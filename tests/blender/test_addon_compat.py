# SPDX-License-Identifier: GPL-3.0-or-later
"""scene/compat.py, the Blender version differences: on this Blender the helpers give what
Blender itself uses (the action's F-curves as keyframe_insert makes them: Action.fcurves
before 4.4, a slot's channelbag from 4.4; SequenceEditor.sequences before 4.4, strips from
4.4), and stand-ins with only the 4.4 / 5.0 names (strips; slots, layers, channelbags and no
Action.fcurves) take the new path. The tests ask Blender for features, not for its version
(compat.py is the one place that reads it). Run through run_in_blender.py."""

from types import SimpleNamespace

import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

from mpeg4face_blender.scene import compat  # noqa: E402

PATH = 'key_blocks["open"].value'
GROUP = "MPEG-4 FAP stream"


@pytest.fixture
def key():
    """A mesh object in the scene with the shape keys Basis and "open": its Key."""
    mesh = bpy.data.meshes.new("compat")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    obj = bpy.data.objects.new("compat", mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.shape_key_add(name="Basis")
    obj.shape_key_add(name="open")
    yield mesh.shape_keys
    for action in [a for a in bpy.data.actions if a.name.startswith("compat")]:
        bpy.data.actions.remove(action)
    bpy.data.objects.remove(obj)
    bpy.data.meshes.remove(mesh)


def test_this_blender_picks_its_api(key):
    # 4.4 renamed Sequence to Strip, the old name gone.
    assert compat.Strip is getattr(bpy.types, "Strip", None) or bpy.types.Sequence
    # Blender's own keying makes a slotted action (4.4 on) or a plain one: compat follows.
    key.key_blocks["open"].value = 0.5  # a new key's value is 0 before 5.0, 1 from 5.0
    key.key_blocks["open"].keyframe_insert("value", frame=1)
    animation = key.animation_data
    animation.action.name = "compat keyed"  # removed by the fixture
    slot = getattr(animation, "action_slot", None)  # AnimData.action_slot: 4.4 on
    assert compat.SLOTTED_ACTIONS is (slot is not None)
    fcurves = compat.action_fcurves(animation)
    assert [c.data_path for c in fcurves] == [PATH]
    assert fcurves[0].evaluate(1) == pytest.approx(0.5)
    if slot is not None:  # the slot's channelbag, the one Blender keyed into
        assert len(animation.action.slots) == 1
        assert fcurves == animation.action.layers[0].strips[0].channelbag(slot).fcurves
    else:
        assert fcurves == animation.action.fcurves


def test_new_fcurve_animates_the_key(key):
    animation = key.animation_data_create()
    animation.action = bpy.data.actions.new("compat")
    for value in (0.25, 0.75):  # the second curve replaces the first
        compat.new_fcurve(animation, PATH, GROUP).keyframe_points.insert(1, value)
    fcurves = compat.action_fcurves(animation)
    assert [c.data_path for c in fcurves] == [PATH]
    assert fcurves[0].group.name == GROUP
    bpy.context.scene.frame_set(1)
    assert key.key_blocks["open"].value == pytest.approx(0.75)
    action = animation.action
    if compat.SLOTTED_ACTIONS:  # in the channelbag of the ID's slot, named after the ID
        slot = animation.action_slot
        assert [s.name_display for s in action.slots] == [key.name]
        assert slot.target_id_type == "KEY"
        bag = action.layers[0].strips[0].channelbag(slot)
        assert fcurves == bag.fcurves and bag.groups.keys() == [GROUP]
        if hasattr(action, "fcurves"):  # 4.4 and 4.5: a proxy for the first slot's curves
            assert list(action.fcurves) == list(fcurves)
    else:  # the action's own list, as bake_stream used it
        assert fcurves == action.fcurves
        assert action.groups.keys() == [GROUP]


def test_reading_fcurves_creates_nothing(key):
    animation = key.animation_data_create()
    assert list(compat.action_fcurves(animation)) == []  # no action
    action = animation.action = bpy.data.actions.new("compat")
    assert list(compat.action_fcurves(animation)) == []  # an empty action
    if compat.SLOTTED_ACTIONS:  # no slot, layer or strip made by reading
        assert animation.action_slot is None
        assert (len(action.slots), len(action.layers)) == (0, 0)
    compat.new_fcurve(animation, PATH, GROUP)
    assert [c.data_path for c in compat.action_fcurves(animation)] == [PATH]


def test_strips_on_this_blender():
    scene = bpy.context.scene
    editor = scene.sequence_editor_create()
    try:
        # 5.0 gives new_effect() a length where it had frame_end (both keyword-only)
        parameters = compat.strips(editor).bl_rna.functions["new_effect"].parameters
        end = {"length": 9} if "length" in parameters else {"frame_end": 10}
        strip = compat.strips(editor).new_effect("compat", "COLOR", 1, 1, **end)
        assert (strip.frame_final_start, strip.frame_final_end) == (1, 10)
        assert isinstance(strip, compat.Strip)
        assert [s.name for s in compat.strips(editor)] == ["compat"]
        # strips from 4.4 (sequences deprecated in 4.4 and 4.5, gone in 5.0), else sequences
        if hasattr(editor, "strips"):
            assert compat.strips(editor) == editor.strips
        else:
            assert compat.strips(editor) == editor.sequences
    finally:
        scene.sequence_editor_clear()


def test_strips_takes_the_4_4_name():
    new, old = [], []
    assert compat.strips(SimpleNamespace(strips=new, sequences=old)) is new  # 4.4, 4.5
    assert compat.strips(SimpleNamespace(strips=new)) is new  # 5.0
    assert compat.strips(SimpleNamespace(sequences=old)) is old  # before 4.4


# --- stand-ins for 4.4's layered actions ---------------------------------------------------


class Made(list):
    """A collection whose new(...) appends and returns make(...)."""

    def __init__(self, make):
        super().__init__()
        self.make = make

    def new(self, *args, **kwargs):
        self.append(self.make(*args, **kwargs))
        return self[-1]

    def get(self, name):
        return next((item for item in self if item.name == name), None)


class FCurves(Made):
    def __init__(self):
        # 4.4's ActionChannelbagFCurves.new(data_path, *, index=0): no action_group
        super().__init__(lambda data_path: SimpleNamespace(data_path=data_path, group=None))

    def find(self, data_path):
        return next((c for c in self if c.data_path == data_path), None)

    def remove(self, curve):
        del self[next(i for i, c in enumerate(self) if c is curve)]


class KeyframeStrip:
    def __init__(self, type):
        self.type = type
        self.channelbags = []

    def channelbag(self, slot, *, ensure=False):
        bag = next((b for b in self.channelbags if b.slot is slot), None)
        if bag is None and ensure:
            bag = SimpleNamespace(slot=slot, fcurves=FCurves(),
                                  groups=Made(lambda name: SimpleNamespace(name=name)))
            self.channelbags.append(bag)
        return bag


def slotted_animation():
    """AnimData of a Key with a new action as 4.4 makes it: no slot, layer or strip yet, and
    (as in 5.0) no Action.fcurves."""
    action = SimpleNamespace(
        slots=Made(lambda id_type, name: SimpleNamespace(id_type=id_type, name=name)),
        layers=Made(lambda name: SimpleNamespace(name=name, strips=Made(KeyframeStrip))))
    return SimpleNamespace(action=action, action_slot=None,
                           id_data=SimpleNamespace(id_type="KEY", name="Key"))


def test_slotted_actions_path(monkeypatch):
    monkeypatch.setattr(compat, "SLOTTED_ACTIONS", True)
    animation = slotted_animation()
    first = compat.new_fcurve(animation, PATH, GROUP)
    [slot] = animation.action.slots
    assert animation.action_slot is slot and (slot.id_type, slot.name) == ("KEY", "Key")
    [layer] = animation.action.layers
    [strip] = layer.strips
    assert strip.type == "KEYFRAME"
    [bag] = strip.channelbags
    assert bag.slot is slot and compat.action_fcurves(animation) is bag.fcurves
    assert bag.fcurves == [first] and first.group is bag.groups.get(GROUP)
    # Again: the same slot, layer, strip and group; the curve of the path replaced.
    second = compat.new_fcurve(animation, PATH, GROUP)
    other = compat.new_fcurve(animation, 'key_blocks["smile"].value', GROUP)
    assert [len(animation.action.slots), len(animation.action.layers), len(layer.strips),
            len(strip.channelbags), len(bag.groups)] == [1, 1, 1, 1, 1]
    assert [id(c) for c in bag.fcurves] == [id(second), id(other)]
    assert second.group is other.group is bag.groups[0]


def test_slotted_actions_read_without_creating(monkeypatch):
    monkeypatch.setattr(compat, "SLOTTED_ACTIONS", True)
    animation = slotted_animation()
    assert list(compat.action_fcurves(animation)) == []
    assert animation.action_slot is None and not animation.action.slots
    assert not animation.action.layers
    first = compat.new_fcurve(animation, PATH, GROUP)
    assert list(compat.action_fcurves(animation)) == [first]


def test_slotted_actions_keep_the_assigned_slot(monkeypatch):
    monkeypatch.setattr(compat, "SLOTTED_ACTIONS", True)
    animation = slotted_animation()
    animation.action_slot = animation.action.slots.new("KEY", "Mine")
    compat.new_fcurve(animation, PATH, GROUP)
    assert [s.name for s in animation.action.slots] == ["Mine"]
    bag = animation.action.layers[0].strips[0].channelbag(animation.action_slot)
    assert bag.fcurves.find(PATH) is not None


def test_the_supported_versions(monkeypatch):
    """3.4 (Debian 12's) and 4.2 LTS and later; any other version is named in one line."""
    for version, ok in (((3, 3, 9), False), ((3, 4, 1), True), ((3, 6, 5), False),
                        ((4, 1, 1), False), ((4, 2, 0), True), ((4, 5, 15), True),
                        ((5, 0, 1), True)):
        monkeypatch.setattr(compat, "bpy", SimpleNamespace(app=SimpleNamespace(version=version)))
        got = compat.unsupported()
        assert (got is None) is ok, version
        if not ok:
            assert got == ("MPEG-4 Face needs Blender 3.4 (Debian 12) or 4.2 LTS and later; "
                           "this is " + ".".join(map(str, version)))


def test_the_label_font_size_is_read_in_every_blender():
    assert compat.label_points(bpy.context.preferences) > 5
