# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's sidebar panels (3D Viewport > Sidebar > MPEG-4), in the order they show:
feature_points (feature points and FAPU; _Sidebar, the base of every panel), faces
(FAP tables and cloning), stream (FAP stream). The motion check and rig panels sit with
their operators (ui/operators/check.py, rig.py)."""
