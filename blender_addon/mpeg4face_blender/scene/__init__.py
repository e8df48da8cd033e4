# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's bpy data layer: reading and writing Blender data (meshes, shape keys,
vertex groups, rigs and pose markers, keyframes, sound strips, draw handlers), with no
operators, panels or properties. It sits between logic/ (bpy-free, which it feeds with
arrays) and ui/ (which reports to the user and calls it), so that the operators, the
samples' scripts and the tests in Blender share one way of reading a head.

- mesh_data: a mesh's coordinates, faces, FP_ groups and shape keys as arrays
- poses: a head with its parts and the rig's poses as one FaceModel
- bake_poses: pose keyframes from an evaluated stream
- stream_data: the grammar keys of an object, a bake's curves written, the stream
  remembered on a head, the scene's frame rate
- live_preview: the live preview's state and frame-change handlers
- live_draw: the live preview drawn with the gpu module
- compat: what differs between Blender versions (3.4, 4.2 LTS and later, 5.0), and which
  ones the add-on supports
"""
