# SPDX-License-Identifier: GPL-3.0-or-later
"""The one place for what differs between Blender versions: Debian 12's 3.4, 4.2 LTS and
later 4.x, 5.0. No other module of the add-on reads bpy.app.version.

- The versions supported: 3.4 and 4.2 and later. On another, unsupported() names what the
  add-on needs and its register() registers the preferences only, which say so.
- How the add-on is installed: 4.2 and later install it as an extension (its
  blender_manifest.toml; the zip of scripts/package.sh, loaded as bl_ext.<repository>.
  mpeg4face, the native module from the wheel it lists); 3.4 as a legacy add-on (bl_info)
  in scripts/addons, which scripts/install_blender_addon.sh finds with user_addon_dir()
  and 4.2 and later still load from there.
- The sequencer (the speech's sound strip): 4.4 renamed bpy.types.Sequence to Strip (the
  old name is gone) and SequenceEditor.sequences to strips (the old name stays, deprecated,
  until 5.0). Strip and strips() give the one this Blender has.
- Actions (the baked stream, pose keys, a rig's shape-key animation): 4.4 made them
  layered, with slots. An action animates an ID through the slot assigned to it, and the
  slot's F-curves sit in a channelbag of a keyframe strip of a layer; Action.fcurves is
  only a proxy for the first slot in 4.4 and 4.5 and goes in 5.0. A channelbag's
  fcurves.new() takes no action_group: the group is set on the curve. action_fcurves()
  reads (and creates nothing), new_fcurve() writes.
- Node groups (the geometry-nodes group that hides a drawn face): 4.0 replaced
  NodeTree.inputs / outputs by NodeTree.interface.new_socket() and flags a modifier's
  group is_modifier, as the modifier's New button does (a script may assign a group
  without it, but the modifier's group selector offers only flagged ones);
  new_modifier_node_group() hides this.
- Materials (the 2D mesh sequence's textured plane): 5.0 gives every material a node tree
  and deprecates Material.use_nodes (setting it warns); material_node_tree() sets it
  before 5.0 only.
- The UI's label font (the sidebar's wrapped labels): ThemeStyle.widget_label in 3.x, gone
  by 4.5, whose labels use the widget font; label_points().
- Drag and drop (a .fap, .fba or .wrl dropped on the 3D viewport): bpy.types.FileHandler from
  4.1, so FILE_HANDLERS is False on 3.4 and ui/file_handlers.py registers nothing there.

The rest of what the add-on calls is the same from 3.4 to 5.0: shape keys and their
foreach_get / foreach_set, FCurve.keyframe_points (add, foreach_set of "co" and
"interpolation"), new_sound()'s arguments, the File menus and operator options, and the gpu
module's create-info shaders (gpu.shader.create_from_info, in 3.4 too: the live preview
needs no GPUShader(vertex, fragment), which 5.0 refuses).
"""

from __future__ import annotations

import bpy

# Blender's version, not a feature test: 4.3 already has Action.slots and .layers behind an
# experimental option, while its animation still reads Action.fcurves.
SLOTTED_ACTIONS = bpy.app.version >= (4, 4, 0)

Strip = getattr(bpy.types, "Strip", None) or bpy.types.Sequence

FILE_HANDLERS = hasattr(bpy.types, "FileHandler")

# 5.0 always uses a material's nodes; setting use_nodes warns there.
_MATERIAL_USE_NODES = bpy.app.version < (5, 0, 0)


def unsupported() -> str | None:
    """Why this Blender cannot run the add-on (one line naming what it needs), None when it
    can: 3.4 (Debian 12's) and 4.2 LTS and later. 3.5 to 4.1 are tested by no one; before
    3.4 the API the add-on calls is missing."""
    version = bpy.app.version
    if version[:2] == (3, 4) or version >= (4, 2, 0):
        return None
    return ("MPEG-4 Face needs Blender 3.4 (Debian 12) or 4.2 LTS and later; this is "
            + ".".join(map(str, version)))


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


def action_fcurves(animation: bpy.types.AnimData
                   ) -> bpy.types.bpy_prop_collection | tuple[()]:
    """The F-curves through which animation.action animates animation's ID; () without an
    action, or (4.4 and later) when no channelbag of the ID's slot holds any. Creates
    nothing: reading an action must not give it a slot, layer or strip."""
    action = animation.action
    if action is None:
        return ()
    if not SLOTTED_ACTIONS:
        return action.fcurves
    slot = animation.action_slot
    bags = (strip.channelbag(slot) for layer in action.layers for strip in layer.strips)
    bag = next((b for b in bags if b is not None), None) if slot is not None else None
    return () if bag is None else bag.fcurves


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


def new_modifier_node_group(name: str) -> bpy.types.GeometryNodeTree:
    """A new geometry-nodes group for a Geometry Nodes modifier, with a Geometry input and
    output socket (and no nodes)."""
    group = bpy.data.node_groups.new(name, "GeometryNodeTree")
    if hasattr(group, "interface"):
        group.is_modifier = True
        for in_out in ("INPUT", "OUTPUT"):
            group.interface.new_socket("Geometry", in_out=in_out,
                                       socket_type="NodeSocketGeometry")
    else:
        group.inputs.new("NodeSocketGeometry", "Geometry")
        group.outputs.new("NodeSocketGeometry", "Geometry")
    return group


def material_node_tree(material: bpy.types.Material) -> bpy.types.ShaderNodeTree:
    """The material's shader nodes, in use (a new material's: the Principled BSDF and the
    Material Output)."""
    if _MATERIAL_USE_NODES:
        material.use_nodes = True
    return material.node_tree


def label_points(preferences: bpy.types.Preferences) -> float:
    """The size in points of the UI's label font (at UI scale 1)."""
    style = preferences.ui_styles[0]
    fonts = style.widget_label if hasattr(style, "widget_label") else style.widget
    return fonts.points
