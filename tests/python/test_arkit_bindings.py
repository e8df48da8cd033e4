# SPDX-License-Identifier: GPL-3.0-or-later
"""mpeg4face's ARKit functions from Python on a small head whose answer is known (the C++
tests' head, tests/cpp/arkit_test_head.hpp, in short): names, shapes, mapping, keys."""

from __future__ import annotations

import numpy as np
import pytest

import mpeg4face

POINTS = {  # metres; FAPU: ES0 0.06, IRISD0 0.012, ENS0 0.05, MNS0 0.03, MW0 0.054
    "3.5": (0.03, 0.03, 0.08), "3.6": (-0.03, 0.03, 0.08), "3.1": (0.03, 0.036, 0.085),
    "3.2": (-0.03, 0.036, 0.085), "3.3": (0.03, 0.024, 0.085), "3.4": (-0.03, 0.024, 0.085),
    "9.15": (0, -0.02, 0.1), "2.2": (0, -0.05, 0.09), "2.3": (0, -0.052, 0.09),
    "2.1": (0, -0.09, 0.08), "8.3": (0.027, -0.051, 0.087), "8.4": (-0.027, -0.051, 0.087),
}


def head(shapes: dict[str, dict[str, tuple[float, float, float]]]) -> mpeg4face.FaceModel:
    ids = list(POINTS)
    coord = np.array([POINTS[i] for i in ids])
    faces = np.array([[0, i, i + 1, -1] for i in range(1, len(ids) - 1)], dtype=np.int32).ravel()
    targets = []
    for name, motion in shapes.items():
        d = np.zeros_like(coord)
        for point, move in motion.items():
            d[ids.index(point)] = move
        targets.append(mpeg4face.MorphTarget(name, d))
    mesh = mpeg4face.IndexedFaceSet("skin", coord, faces, morph_targets=targets)
    model = mpeg4face.FaceModel(meshes=[mesh], transforms=[mpeg4face.Transform("skin", meshes=[0])],
                                roots=[0])
    model.feature_points = {i: mpeg4face.FeaturePointBinding(0, k) for k, i in enumerate(ids)}
    return model


def test_names_and_spellings():
    names = mpeg4face.arkit_shape_names()
    assert len(names) == 52 and names[0] == "eyeBlinkLeft" and names[-1] == "tongueOut"
    assert mpeg4face.arkit_shape_index("blendShape1.eyeBlink_L")["shape"] == "eyeBlinkLeft"
    assert mpeg4face.arkit_shape_index("browInnerUp_R") == {"shape": "browInnerUp", "index": 43,
                                                             "half": "right"}
    assert mpeg4face.arkit_shape_index("fap3_open_jaw@100") is None


def test_keys_from_a_jaw_and_a_blink():
    model = head({"JawOpen": {"2.1": (0, -0.01, 0), "2.3": (0, -0.01, 0)},
                  "eyeBlink_L": {"3.1": (0, -0.01, 0)}})
    assert [s["shape"] for s in mpeg4face.find_arkit_shapes(model)] == ["eyeBlinkLeft", "jawOpen"]
    made = mpeg4face.arkit_fap_keys(model)
    keys = {k["name"]: k for k in made["mapping"]}
    assert keys["fap3_open_jaw@341"]["weights"] == pytest.approx({"JawOpen": 341 / 341.333},
                                                                  abs=1e-6)
    assert "fap19_close_t_l_eyelid@853" in keys
    assert any(m["fap"] == 27 and m["reason"] for m in made["missed"])
    names = {t.name for t in made["head"].meshes[0].morph_targets}
    assert "fap3_open_jaw@341" in names and any(n.startswith("viseme") for n in names)
    # anger's FAPs (brows, lids, lips pressed) have no key here, so it has no key either;
    # joy and surprise part the lips (FAP 5 down, keyed by JawOpen)
    assert "expression3_anger" not in names
    assert "expression1_joy" in names and "expression6_surprise" in names
    assert mpeg4face.generate_face(made["head"])["copies"] == len(names) - 2  # not the ARKit shapes


def test_a_head_without_arkit_shapes_is_refused():
    with pytest.raises(mpeg4face.Error, match="looked for eyeBlinkLeft"):
        mpeg4face.arkit_fap_keys(head({}))
