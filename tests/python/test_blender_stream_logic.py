# SPDX-License-Identifier: GPL-3.0-or-later
"""The Blender add-on's bpy-free stream layer: shape key weights by the FAT rule (several
amplitudes, extrapolation, the negative side), visemes, expressions, resampling, frame
rates, and a whole bake of joy.fap."""

import numpy as np
import pytest

import mpeg4face
from mpeg4face_blender.logic import stream as sl


def test_face_keys_sorts_ours_and_lists_malformed():
    keys = sl.face_keys(["Basis", "fap3_open_jaw@512", "viseme1", "expression2@40",
                         "fap3@512.001", "smile"])
    assert [(k.name, k.fap, k.select, k.amplitude) for k in keys.keys] == [
        ("fap3_open_jaw@512", 3, 0, 512), ("viseme1", 1, 1, 63), ("expression2@40", 2, 2, 40)]
    assert len(keys.malformed) == 1 and keys.malformed[0].startswith("fap3@512.001: ")
    assert [k.name for k in keys.of(3)] == ["fap3_open_jaw@512"]


def test_one_amplitude_is_linear_both_ways():
    w = sl.border_weights([0, 256, 512, 1024, -128], [512])
    np.testing.assert_allclose(w[:, 0], [0, 0.5, 1, 2, -0.25])


def test_several_amplitudes_piecewise_with_extrapolation():
    amplitudes = [512, 256, -200]
    w = sl.border_weights([128, 256, 384, 768, -100, -400, 0], amplitudes)
    np.testing.assert_allclose(w, [
        [0, 0.5, 0],        # between Basis and 256
        [0, 1, 0],          # at 256
        [0.5, 0.5, 0],      # between 256 and 512
        [2, -1, 0],         # beyond 512: [256, 512] continues, t = 2
        [0, 0, 0.5],        # negative side, between -200 and Basis
        [0, 0, 2],          # beyond -200: [-200, 0] continues
        [0, 0, 0],          # the Basis
    ], atol=1e-12)


def test_repeated_amplitudes_share_the_weight():
    np.testing.assert_allclose(sl.border_weights([300], [600, 600]), [[0.5, 0.5]])


def test_viseme_weights():
    rows = [[3, 5, 63, 0], [3, 5, 21, 0], [5, 3, 0, 0], [3, 3, 10, 0], [0, 0, 0, 0]]
    np.testing.assert_allclose(sl.viseme_weights(rows, 3), [1, 21 / 63, 1, 1, 0])
    np.testing.assert_allclose(sl.viseme_weights(rows, 5), [0, 42 / 63, 0, 0, 0])


def test_expression_weights():
    rows = [[1, 40, 4, 20, 0, 0], [4, 63, 1, 10, 0, 0], [1, 20, 1, 20, 0, 0]]
    key = sl.FaceKey("expression1@40", 2, 1, 40)
    np.testing.assert_allclose(sl.expression_weights(rows, [key])[:, 0], [1, 0.25, 1])
    full = sl.FaceKey("expression4", 2, 4, 63)
    np.testing.assert_allclose(sl.expression_weights(rows, [full])[:, 0], [20 / 63, 1, 0])


def test_sent_selects_ignore_neutral_and_weightless():
    visemes = np.array([[3, 5, 63, 0], [0, 7, 0, 0]])
    assert sl.sent_selects(1, visemes) == {3, 7}
    expressions = np.array([[1, 40, 2, 0, 0, 0]])
    assert sl.sent_selects(2, expressions) == {1}


def test_resample_hold_and_linear():
    times = np.array([0.0, 0.1, 0.3])
    rows = np.array([[0.0], [10.0], [30.0]])
    at = np.array([0.0, 0.05, 0.1, 0.2, 0.3, 0.5])
    np.testing.assert_allclose(sl.resample(times, rows, at, "HOLD")[:, 0], [0, 0, 10, 10, 30, 30])
    np.testing.assert_allclose(sl.resample(times, rows, at, "LINEAR")[:, 0], [0, 5, 10, 20, 30, 30])
    with pytest.raises(ValueError, match="CUBIC"):
        sl.resample(times, rows, at, "CUBIC")


def test_frame_rates_and_counts():
    assert sl.scene_fps(25.0) == (25, 1.0)
    fps, base = sl.scene_fps(29.97)
    assert fps == 30 and fps / base == pytest.approx(29.97)
    assert sl.scene_frame_count(4.32, 25.0) == 108
    assert sl.scene_frame_count(4.32, 30.0) == 130
    assert sl.live_index([0, 2, 5], 25.0, 0.0) == 0
    assert sl.live_index([0, 2, 5], 25.0, 3 / 25) == 1
    assert sl.live_index([0, 2, 5], 25.0, 10.0) == 2


def test_widened_slider():
    assert sl.widened_slider((0.0, 1.0), (0.2, 0.8)) == (0.0, 1.0, False)
    assert sl.widened_slider((0.0, 1.0), (-0.5, 2.5)) == (-0.5, 2.5, False)
    assert sl.widened_slider((0.0, 1.0), (-12.0, 3.0)) == (-10.0, 3.0, True)


def stream(frames, columns, visemes=None, expressions=None, rate=25.0):
    """A stream sending FAPs {fap: values per frame} at the given frame numbers."""
    mask = np.zeros((len(frames), 68), bool)
    values = np.zeros((len(frames), 68), np.int32)
    for fap, v in columns.items():
        mask[:, fap - 1] = True
        values[:, fap - 1] = v
    return mpeg4face.FapStream.from_arrays(frames, mask, values, visemes, expressions, rate)


def test_bake_low_level_hold_and_linear():
    s = stream([0, 2, 4], {3: [0, 256, 1024], 5: [10, 10, 10]})
    keys = sl.face_keys(["fap3@512", "fap3@1024", "fap6@100"])
    held = sl.bake(s, keys, 25.0, "HOLD")
    assert held.frames == 5
    np.testing.assert_allclose(held.curves["fap3@512"], [0, 0, 0.5, 0.5, 0])
    np.testing.assert_allclose(held.curves["fap3@1024"], [0, 0, 0, 0, 1])
    np.testing.assert_allclose(held.curves["fap6@100"], 0)  # not sent: Basis
    assert held.baked_faps == [3]
    assert held.missing == ["FAP 5 (raise_b_midlip)"]
    linear = sl.bake(s, keys, 25.0, "LINEAR")
    # frame 3: 640 lies in [512, 1024], t = 0.25
    np.testing.assert_allclose(linear.curves["fap3@512"], [0, 0.25, 0.5, 0.75, 0])
    np.testing.assert_allclose(linear.curves["fap3@1024"], [0, 0, 0, 0.25, 1])


def test_bake_visemes_and_expressions():
    visemes = [[3, 5, 21, 0], [3, 5, 21, 0]]
    expressions = [[1, 40, 6, 63, 0, 0], [1, 20, 6, 63, 0, 0]]
    s = stream([0, 1], {1: [0, 0], 2: [0, 0]}, visemes, expressions)
    keys = sl.face_keys(["viseme3", "expression1@40", "fap3@512"])
    b = sl.bake(s, keys, 25.0)
    np.testing.assert_allclose(b.curves["viseme3"], [1 / 3, 1 / 3])
    np.testing.assert_allclose(b.curves["expression1@40"], [1, 0.5])
    assert b.baked_faps == [1, 2]
    assert b.missing == ["viseme 5", "expression 6"]


def test_bake_resamples_to_the_scene_rate(data_dir):
    s = mpeg4face.read_fap_stream(data_dir / "xface-fap" / "joy.fap")
    values = s.resolved()["values"][:, 2]
    keys = sl.face_keys(["fap3_open_jaw@512"])
    same = sl.bake(s, keys, 25.0)
    assert same.frames == len(s) == 108
    np.testing.assert_allclose(same.curves["fap3_open_jaw@512"], values / 512)
    assert 3 in same.baked_faps and "FAP 4 (lower_t_midlip)" in same.missing
    fast = sl.bake(s, keys, 50.0, "LINEAR")
    assert fast.frames == 216
    np.testing.assert_allclose(fast.curves["fap3_open_jaw@512"][::2], values / 512)
    np.testing.assert_allclose(fast.curves["fap3_open_jaw@512"][21],
                               (values[10] + values[11]) / 2 / 512)


def test_bake_of_an_empty_stream_is_refused():
    with pytest.raises(ValueError, match="no frames"):
        sl.bake(mpeg4face.FapStream(), sl.face_keys(["fap3@512"]), 25.0)


def test_encoding_summary():
    assert sl.encoding_summary(9128, 2112.96, 47.752) == "9128 bits, 2113.0 bit/s, PSNR 47.75 dB"
    assert sl.encoding_summary(20752, 4803.7, float("inf")).endswith("lossless")
    assert sl.encoding_summary(0, 0.0, None).endswith("no PSNR")
    assert sl.encoding_summary(0, 0.0, float("nan")).endswith("no PSNR")



def test_animated_faps_are_the_sent_held_and_mirrored_ones():
    # FAP 19 sent in frame 0 (held after it, and mirrored onto 20, which is never sent),
    # a viseme in frame 1; nothing else: the live preview needs the tables of these only.
    count = 3
    mask = np.zeros((count, 68), dtype=bool)
    values = np.zeros((count, 68), dtype=np.int32)
    mask[0, 18], values[0, 18] = True, 100
    mask[1, 0] = True
    visemes = np.zeros((count, 4), dtype=np.int32)
    visemes[1] = (3, 0, 63, 0)
    stream = mpeg4face.FapStream.from_arrays(np.arange(count, dtype=np.int32), mask, values,
                                             visemes=visemes)
    assert sl.animated_faps(stream) == {1, 19, 20}


def test_frame_ranges():
    assert sl.frame_ranges([3, 4, 5, 9, 11, 12]) == "3-5, 9, 11-12"
    assert sl.frame_ranges([7]) == "7"
    assert sl.frame_ranges([]) == ""
