# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's bpy-free rig layer: which shape keys are the rig's, the messages refusing a
rig, the FAP -> bone mapping table and the iterative fit of a bone's motion."""

import math

import numpy as np
import pytest

from mpeg4face_blender.logic import rig as rig_logic


def test_animated_keys_come_from_driver_and_action_paths():
    paths = ['key_blocks["jaw_corrective"].value', 'key_blocks["say \\"a\\""].value',
             'key_blocks["x"].slider_max', "eval_time"]
    assert rig_logic.animated_key_names(paths) == {"jaw_corrective", 'say "a"'}


def test_topology_message_names_the_modifier():
    message = rig_logic.topology_message("head", 100, 400, [("Armature", "ARMATURE"),
                                                            ("Subdivision", "SUBSURF")])
    assert message.startswith("head: Subsurf 'Subdivision' changes its vertex count "
                              "(100 -> 400)")
    assert "Armature" not in message.split(";")[0]
    assert "one of its modifiers" in rig_logic.topology_message("head", 1, 2, [])


def test_still_copies_and_unmoved_feature_points():
    assert not rig_logic.moves(np.full((4, 3), 1e-8), 1.0)
    assert rig_logic.moves(np.full((4, 3), 1e-3), 1.0)
    copy = np.zeros((5, 3))
    copy[3] = (0, -0.1, 0)  # the jaw moves vertex 3; the chin 2.1 is vertex 2
    point = ("2.1", "head", 2)
    message = rig_logic.unmoved_feature_point_message("fap3_open_jaw@512", {"head": copy},
                                                      point)
    assert message.startswith("pose marker fap3_open_jaw@512: the rig moves the skin but "
                              "not feature point 2.1 (FAP 3 open_jaw's, vertex 2 of head)")
    copy[2] = (0, -0.05, 0)
    assert rig_logic.unmoved_feature_point_message("fap3_open_jaw@512", {"head": copy},
                                                   point) is None
    # Only the teeth move: the head's chin does not.
    assert rig_logic.unmoved_feature_point_message("fap3_open_jaw@512", {"teeth": copy},
                                                   point) is not None
    # Nothing moved (a pose of Transforms), visemes, unbound points: no complaint.
    assert rig_logic.unmoved_feature_point_message("fap3_open_jaw@512", {}, point) is None
    assert rig_logic.unmoved_feature_point_message("viseme1_p_b_m", {"head": copy},
                                                   point) is None
    assert rig_logic.unmoved_feature_point_message("fap3_open_jaw@512", {"head": copy},
                                                   None) is None


def test_mapping_round_trips_and_names_bad_entries():
    mapping = rig_logic.mapping_from_json(rig_logic.mapping_to_json(rig_logic.RIGIFY_MAPPING))
    assert mapping == rig_logic.RIGIFY_MAPPING
    assert rig_logic.mapping_from_json('{"31": "brow_in.L", "4": ["lip.L", "lip.R"]}') == {
        31: rig_logic.BoneChannel("brow_in.L"), 4: rig_logic.BoneChannel("lip.L", also=("lip.R",))}
    assert rig_logic.RIGIFY_MAPPING[4].bones == ("lip.T.L", "lip.T.R")
    for text, error in (('{"2": "jaw"}', "FAP 2: not a low-level FAP number"),
                        ('{"3": {"bone": "jaw", "channel": "scale"}}', "channel must be"),
                        ('{"3": {"bone": "jaw", "axis": "W"}}', "axis must be"),
                        ('{"3": {"bone": "jaw", "roll": 1}}', "unknown field roll"),
                        ('{"3": 7}', "expected a bone name"),
                        ('{"3": []}', "expected a bone name"),
                        ('{"3": "jaw",}', "map.json: line 1, column")):
        with pytest.raises(ValueError, match=error):
            rig_logic.mapping_from_json(text, "map.json")


def test_fit_pose_corrects_until_within_tolerance():
    # A jaw: the chin on a circle of radius 0.1 about the pivot; down is -Y.
    def chin(angle):
        return np.array([0.0, -0.1 * math.sin(angle), -0.1 * (1 - math.cos(angle))])

    down = np.array([0.0, -1.0, 0.0])
    fit = rig_logic.fit_pose(3, chin, down, 0.06, first=0.1)
    assert fit.ok and abs(fit.reached - 1.0) <= 0.05
    assert 0.06 * 0.95 <= -chin(fit.value)[1] <= 0.06 * 1.05
    # A bone that does not move the point.
    still = rig_logic.fit_pose(3, lambda _: np.zeros(3), down, 0.06, first=0.1)
    assert not still.ok and "does not move" in still.reason
    # Out of reach: the circle's 0.1 can not give 0.2.
    far = rig_logic.fit_pose(3, chin, down, 0.2, first=0.1)
    assert not far.ok
