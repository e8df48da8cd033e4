# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's bpy-free ARKit layer: which shape keys are ARKit blendshapes, the keys
arkit_fap_keys makes on CANDIDE-3 with a few ARKit shapes (back in Blender's axes), the
report of the FAPs made and missed, and where a converted capture goes."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import mpeg4face
from mpeg4face_blender.logic import arkit as arkit_logic
from mpeg4face_blender.logic import feature_points, shape_keys

# The ARKit shapes of the Blender test (tests/blender/conftest.py is bpy-free at import).
_spec = importlib.util.spec_from_file_location(
    "blender_conftest", Path(__file__).resolve().parent.parent / "blender" / "conftest.py")
blender_conftest = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(blender_conftest)


@pytest.fixture(scope="module")
def candide(data_dir):
    """CANDIDE-3 as a FaceModel with the ARKit shapes jawOpen, eyeBlink_L, MouthSmileLeft
    and a key of the user's, Smirk; and its feature points' vertices."""
    model = mpeg4face.read_model(data_dir / "candide3" / "candide3.wfm")
    points, _ = mpeg4face.read_feature_point_csv(data_dir / "candide3" / "feature_points.csv",
                                                 model)
    fp_vertices = {fp: b.vertex for fp, b in points.items()}
    mesh = model.meshes[0]
    shapes = blender_conftest.candide_arkit_shapes(mesh.coord, fp_vertices)
    shapes["Smirk"] = np.zeros_like(mesh.coord)
    model = feature_points.face_model_from_arrays(mesh.coord, mesh.coord_index, fp_vertices, shapes)
    return model, fp_vertices


@pytest.fixture(scope="module")
def keys(candide):
    model, _ = candide
    return mpeg4face.arkit_fap_keys(model)


def test_arkit_key_names():
    names = ["Basis", "jawOpen", "eyeBlink_L", "EyeBlinkRight", "blendShape1.mouthSmileLeft",
             "Smirk", "fap3_open_jaw@512", "viseme1"]
    assert arkit_logic.arkit_key_names(names) == [
        "jawOpen", "eyeBlink_L", "EyeBlinkRight", "blendShape1.mouthSmileLeft"]


def test_made_keys_move_the_feature_points_in_blenders_axes(candide, keys):
    model, fp_vertices = candide
    made = arkit_logic.made_keys(keys["head"])
    assert made and all(not n.startswith(("jawOpen", "Smirk")) for n in made)
    [jaw] = [k for k in keys["mapping"] if k["fap"] == 3 and k["amplitude"] > 0]
    # FAP 3 at its amplitude drops the chin by amplitude MNS units: Blender's -Z.
    mns = mpeg4face.measure_fapu(model).unit("MNS")
    chin = made[jaw["name"]][fp_vertices["2.1"]]
    assert chin[2] == pytest.approx(-jaw["amplitude"] * mns, rel=0.15)
    assert abs(chin[0]) < 1e-9 and abs(chin[1]) < 0.15 * abs(chin[2])
    assert any(n.startswith("viseme") for n in made)


def test_keys_report(keys):
    made = arkit_logic.made_keys(keys["head"])
    report = arkit_logic.keys_report("candide3", keys, list(made), replaced=0)
    assert len(report.made) == len(keys["mapping"]) and len(report.missed) == len(keys["missed"])
    assert report.visemes + report.expressions + len(report.made) + report.held == len(made)
    # Every FAP key but the jaw's and the eyeball turns' is held past its reach, by one copy
    # (_held) or two (_reach, _held): docs/arkit.md, "Held keys".
    held = [n for n in made if shape_keys.parse(n)["label"].endswith("_held")]
    assert len(held) == sum(k["fap"] not in (3, 14, 15) and k["transform"] is None
                            for k in keys["mapping"])
    assert len(held) <= report.held <= 2 * len(held)
    assert report.summary().startswith(f"candide3: {len(report.made)} FAP keys, ")
    assert any(r.startswith("fap3_open_jaw@") for r in report.made)
    # The tongue has no ARKit shape here: missed, with the core's reason.
    assert any(r.startswith("fap43 ") for r in report.missed)
    lines = report.lines()
    assert lines[0] == report.summary() and "Missed:" in lines


def test_report_rows():
    result = {"mapping": [
        {"fap": 3, "amplitude": 500, "name": "fap3_open_jaw@500", "reached": 1.0,
         "residual": 0.123},
        {"fap": 23, "amplitude": 50000, "name": "fap23_yaw_l_eyeball@50000", "reached": 0.8,
         "residual": 0.0}],
        "missed": [{"fap": 43, "sign": 0, "reason": "no ARKit shape moves 6.1"},
                   {"fap": 6, "sign": -1, "reason": "no shape moves 8.3 inwards"}],
        "warnings": ["MW0 is odd"]}
    report = arkit_logic.keys_report(
        "head", result, ["fap3_open_jaw@500", "viseme1_p_b_m", "expression1_joy"], replaced=2)
    assert report.made == ["fap3_open_jaw@500: residual 0.12",
                           "fap23_yaw_l_eyeball@50000: residual 0.00, reached 80% (a pose of "
                           "a Transform: not written)"]
    assert report.missed == ["fap43 shift_tongue_tip: no ARKit shape moves 6.1",
                             "fap6 stretch_l_cornerlip -: no shape moves 8.3 inwards"]
    assert (report.visemes, report.expressions, report.replaced) == (1, 1, 2)
    assert report.lines()[-1] == "warning: MW0 is odd"


def test_capture_stream_path(tmp_path):
    assert arkit_logic.capture_stream_path(tmp_path, "Head.001", "/x/My Slate 3.csv") == \
        tmp_path / "Head.001-My_Slate_3.fap"
