# SPDX-License-Identifier: GPL-3.0-or-later
"""The one place for what differs between Blender versions (3.4 up to 4.x and 5.0).

- The user add-on folder: scripts/addons in 3.x and 4.x. Blender 4.2's extensions live in
  another folder and need a blender_manifest.toml; this add-on installs as a legacy add-on
  (bl_info, no manifest), which 4.2 and later still load from scripts/addons.
- The sequencer (the speech's sound strip): 4.4 renamed bpy.types.Sequence to Strip (the
  old name is gone) and SequenceEditor.sequences to strips (the old name stays, deprecated,
  until 5.0). Strip and strips() give the one this Blender has.
- Actions (the baked stream): 4.4 made them layered, with slots. An action animates an ID
  through the slot assigned to it, and the slot's F-curves sit in a channelbag of a keyframe
  strip of a layer; Action.fcurves is only a proxy for the first slot in 4.4 and 4.5 and
  goes in 5.0. A channelbag's fcurves.new() takes no action_group: the group is set on the
  curve. action_fcurves() and new_fcurve() hide this.

The rest of what the add-on calls is the same from 3.4 to 4.x: shape keys and their
foreach_get / foreach_set, FCurve.keyframe_points (add, foreach_set of "co" and
"interpolation"), new_sound()'s arguments, the File menus and operator options.
"""

from __future__ import annotations

import bpy

# Blender's version, not a feature test: 4.3 already has Action.slots and .layers behind an
# experimental option, while its animation still reads Action.fcurves.
SLOTTED_ACTIONS = bpy.app.version >= (4, 4, 0)

Strip = getattr(bpy.types, "Strip", None) or bpy.types.Sequence


def user_addon_dir() -> str:
    """Blender's user add-on folder (BLENDER_USER_SCRIPTS moves it)."""
    return bpy.utils.user_resource("SCRIPTS", path="addons", create=True)


def strips(editor: bpy.types.SequenceEditor) -> bpy.types.bpy_prop_collection:
    """The sequence editor's top-level strips (new_sound(), remove(), iteration)."""
    return editor.strips if hasattr(editor, "strips") else editor.sequences


def _channelbag(animation: bpy.types.AnimData) -> bpy.types.bpy_struct:
    """The channelbag of the ID's slot in the first keyframe strip of the action's first
    layer; the slot (assigned to the ID, named after it), layer and strip are created when
    missing."""
    action = animation.action
    if animation.action_slot is None:
        owner = animation.id_data
        animation.action_slot = action.slots.new(id_type=owner.id_type, name=owner.name)
    layer = action.layers[0] if len(action.layers) else action.layers.new("Layer")
    strip = layer.strips[0] if len(layer.strips) else layer.strips.new(type="KEYFRAME")
    return strip.channelbag(animation.action_slot, ensure=True)


def action_fcurves(animation: bpy.types.AnimData) -> bpy.types.bpy_prop_collection:
    """The F-curves through which animation.action (set) animates animation's ID."""
    return _channelbag(animation).fcurves if SLOTTED_ACTIONS else animation.action.fcurves


def new_fcurve(animation: bpy.types.AnimData, data_path: str, group: str) -> bpy.types.FCurve:
    """A new, empty F-curve of data_path in the action group `group`, replacing the curve of
    that path animation.action had."""
    channelbag = _channelbag(animation) if SLOTTED_ACTIONS else None
    fcurves = animation.action.fcurves if channelbag is None else channelbag.fcurves
    old = fcurves.find(data_path)
    if old is not None:
        fcurves.remove(old)
    if channelbag is None:
        return fcurves.new(data_path, action_group=group)
    curve = fcurves.new(data_path)
    curve.group = channelbag.groups.get(group) or channelbag.groups.new(group)
    return curve
