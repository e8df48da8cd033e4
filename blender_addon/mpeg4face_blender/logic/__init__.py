# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's bpy-free layer: what the operators and panels compute, from plain arrays,
names and mpeg4face objects (numpy and the mpeg4face module only). Nothing here imports
bpy, bmesh, mathutils or any other Blender module, so plain pytest tests it
(tests/python/test_blender_*.py; test_blender_addon_layout.py fails if one does).

- feature_points: the FP_ vertex groups, the feature point rows, FAPU read-outs, a
  FaceModel and the panel's FaceState built from arrays
- shape_keys: the shape-key grammar (fap<N>_<label>@<value>, viseme<N>, expression<N>),
  the FAP tables from keys
- arkit: FAP, viseme and expression keys from ARKit blendshapes
- rig: a rig's bones mapped to FAPs, pose markers
- stream: FAP streams baked into curves, the live index, encoding summaries
- live: the live preview's placement of evaluated coordinates
- check: the motion check's read-out
- face_import: an MPEG-4 face (.wrl) as the objects, FP_ groups and grammar keys to make

The bpy layers import stream, live, rig, arkit and check as <name>_logic (their operator
modules in ui/operators/ have the same concern names); feature_points and shape_keys by
their own names.
"""
