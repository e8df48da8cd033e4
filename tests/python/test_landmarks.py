# SPDX-License-Identifier: GPL-3.0-or-later
"""mpeg4face.find_feature_points across heads (docs/landmarks.md): each sample head's points
found with the other sample as template, as it is, turned, rescaled and moved, decimated and
subdivided (scripts/landmarks_evaluation.py prints the same figures). The C++ tests hold a
head found from itself, remeshed, pinned, and the heads that are no face."""

from __future__ import annotations

import sys
from pathlib import Path

import mpeg4face
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import landmarks_evaluation as evaluation  # noqa: E402

# The named points whose place geometry defines: lip corners and contact points, outer lip
# mid points, eye corners, nose tip and subnasale. The brow ends are not among them: the
# MakeHuman head's brows are placed by CANDIDE-3's proportions from the eye corners, the ICT
# head's on its scanned brows, 25-30% of ES0 apart (docs/landmarks.md, Figures).
GEOMETRIC = [p for p in evaluation.NAMED if not p.startswith("4.")]


@pytest.fixture(scope="module")
def cases():
    found = evaluation.cases()
    print(evaluation.report(found))
    return {c.name: c for c in found}


def test_each_sample_heads_points_are_found_from_the_other(cases):
    for name, case in cases.items():
        named = 100 * np.array([case.errors[p] for p in GEOMETRIC])
        lips = 100 * np.array([case.errors[p] for p in evaluation.GROUPS["lips"].split()])
        eyes = 100 * np.array([case.errors[p] for p in evaluation.GROUPS["eyes"].split()])
        print(f"{name}: geometric named points median {np.median(named):.1f}, p90 "
              f"{np.percentile(named, 90):.1f}, max {named.max():.1f} % of ES0")
        assert np.median(named) < 5.5 and np.percentile(named, 90) < 9 and named.max() < 10, name
        assert np.median(lips) < 6 and np.median(eyes) < 4, name
        # Every point the template has is placed (MakeHuman has no 11.5: the ICT head lacks it).
        assert len(case.errors) >= 84, name
        # ES0 from the pupils: within 8% (MakeHuman's pupils are an iris vertex, not the
        # cornea's apex); MW0 from the lip corners within 10%.
        assert case.fapu["es0"] < 0.08 and case.fapu["mw0"] < 0.1, name


def test_eye_teeth_and_tongue_points_are_found_on_their_own_meshes(cases):
    # Upper and lower teeth meet in a closed mouth: the mesh nearest a point alone put the
    # lower teeth's 9.11 on the upper row and the tongue tip 6.1 on the lower teeth, so the
    # teeth and tongue were no rigid parts to cloning (docs/landmarks.md).
    for name, case in cases.items():
        assert len(case.parts) >= 10, name
        wrong = {fp: found for fp, (found, own) in case.parts.items() if found != own}
        assert not wrong, f"{name}: {wrong}"


def test_the_points_do_not_depend_on_the_heads_axes_size_or_place(cases):
    for target in ("MakeHuman from ICT", "ICT from MakeHuman"):
        a = cases[f"{target}, as it is"].errors
        b = cases[f"{target}, turned, rescaled, moved"].errors
        same = [abs(a[p] - b[p]) < 0.01 for p in a]
        assert np.mean(same) > 0.97, target


def test_pins_and_progress_from_python():
    heads = evaluation.heads()
    target, truth = evaluation.moved(heads["MakeHuman"], np.eye(3), np.zeros(3))
    pins = {p: mpeg4face.FeaturePointBinding(position=truth[p]) for p in ("8.3", "8.4", "9.3")}
    steps = []
    points, info = mpeg4face.find_feature_points(
        target, heads["ICT"], pins=pins, progress=lambda f, s: steps.append((f, s)))
    for p in pins:
        binding, confidence, rule = points[p]
        assert rule == "pin" and confidence == 1
        assert np.array_equal(binding.position, truth[p])
    assert steps[0] == (0.0, "alignment") and steps[-1] == (1.0, "done")
    assert info["alignment"].shape == (4, 4) and info["not_placed"] == []
    with pytest.raises(TypeError, match=r"pins\['2.1'\]"):
        mpeg4face.find_feature_points(target, heads["ICT"], pins={"2.1": (0, 0, 0)})


def test_the_lids_and_outer_eye_corners_sit_at_the_edge_of_the_eyes_opening(cases):
    # Seen from the front, where the eye gives way to the skin (docs/landmarks.md, "Rules of
    # their own"): the fit alone left the ICT head's lower lids 5% of ES0 low (IRISD0 25% off)
    # and both heads' outer corners 5-8% of ES0 off; on a decimated MakeHuman the margin's
    # nearest vertex was one the lid hides, 7.5% of ES0 deep.
    for name, case in cases.items():
        lids = 100 * np.array([case.errors[p] for p in ("3.1", "3.2", "3.3", "3.4")])
        corners = 100 * np.array([case.errors[p] for p in ("3.7", "3.12")])
        assert lids.max() < 3.5 and corners.max() < 3.5, (name, lids, corners)
    assert cases["ICT from MakeHuman, as it is"].fapu["irisd0"] < 0.05
