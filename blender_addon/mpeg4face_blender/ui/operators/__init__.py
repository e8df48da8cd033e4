# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's operators, a module per concern: feature_points (assign, mirror; and
active_mesh, which every operator uses), faces (FAP tables, clone), arkit, rig, check
(the motion check), and for FAP streams: stream (what they share), bake, live, encode,
speech, import_stream; import_mesh2d and export (File menu entries). Each checks its
input and reports problems in the UI instead of raising."""
