# SPDX-License-Identifier: GPL-3.0-or-later
"""FAP streams from Python: arrays in and out, .fap files, the FBA codec, PSNR, speech."""

import wave

import numpy as np
import pytest

import mpeg4face


@pytest.fixture(scope="module")
def joy(data_dir):
    return mpeg4face.read_fap(data_dir / "xface-fap" / "joy.fap")


def test_arrays_of_a_fap_file(joy, data_dir):
    assert len(joy) == 108
    assert joy.frame_rate == 25
    assert joy.duration == pytest.approx(108 / 25)
    numbers, mask, values = joy.frame_numbers, joy.mask, joy.values
    assert numbers.shape == (108,) and numbers.dtype == np.int32
    assert mask.shape == (108, 68) and mask.dtype == np.bool_
    assert values.shape == (108, 68) and values.dtype == np.int32
    assert list(numbers[:3]) == [0, 1, 2]
    # joy.fap's first mask line sends FAP 3 (open_jaw), not FAP 1 and 2.
    first_mask = (data_dir / "xface-fap" / "joy.fap").read_text().splitlines()[1].split()
    assert list(mask[0]) == [bit == "1" for bit in first_mask]
    assert not mask[:, 0].any() and not mask[:, 1].any()
    # Values only where sent; the arrays are copies.
    assert (values[~mask] == 0).all()
    values[0, 2] = 12345
    assert joy.values[0, 2] != 12345
    assert joy.visemes.shape == (108, 4) and joy.expressions.shape == (108, 6)


def test_from_arrays_round_trips_through_a_fap_file(joy, tmp_path):
    again = mpeg4face.FapStream.from_arrays(
        joy.frame_numbers, joy.mask, joy.values, joy.visemes, joy.expressions,
        frame_rate=joy.frame_rate, name=joy.name)
    assert again == joy
    path = tmp_path / "copy.fap"
    mpeg4face.write_fap(again, path)
    assert mpeg4face.read_fap(path) == joy

    # A stream with visemes and an expression, built from scratch.
    n = 5
    mask = np.zeros((n, 68), bool)
    mask[:, [0, 1, 2]] = True
    values = np.zeros((n, 68), np.int32)
    values[:, 2] = np.arange(n) * 100
    visemes = np.array([[i % 15, 0, 63, 0] for i in range(n)])
    expressions = np.array([[1, 10 * i, 0, 0, 0, 0] for i in range(n)])
    s = mpeg4face.FapStream.from_arrays(np.arange(n), mask, values, visemes, expressions,
                                        frame_rate=30, name="built")
    assert repr(s) == "<FapStream 'built': 5 frames at 30 Hz>"
    np.testing.assert_array_equal(s.visemes, visemes)
    np.testing.assert_array_equal(s.expressions, expressions)
    np.testing.assert_array_equal(s.values[:, 2], values[:, 2])


def test_from_arrays_names_bad_input():
    mask = np.zeros((2, 68), bool)
    values = np.zeros((2, 68), np.int32)
    with pytest.raises(ValueError, match=r"mask: expected a boolean array of shape \(2, 68\)"):
        mpeg4face.FapStream.from_arrays([0, 1], mask[:, :10], values)
    with pytest.raises(ValueError, match=r"values: expected an array of shape \(2, 68\)"):
        mpeg4face.FapStream.from_arrays([0, 1], mask, values[:1])
    mask[0, 0] = True
    with pytest.raises(ValueError, match="visemes: needed, since mask sets FAP 1"):
        mpeg4face.FapStream.from_arrays([0, 1], mask, values)
    mask[0, 0] = False
    mask[1, 5] = True
    wide = values.astype(np.int64)
    wide[1, 5] = 2**40
    with pytest.raises(ValueError, match=r"values\[1\]: 1099511627776 does not fit an int"):
        mpeg4face.FapStream.from_arrays([0, 1], mask, wide)


def test_resolved_holds_values_and_mirrors_the_unsent_side():
    mask = np.zeros((3, 68), bool)
    values = np.zeros((3, 68), np.int64)
    mask[0, 5] = True  # FAP 6 stretch_l_cornerlip, its partner FAP 7 never sent
    values[0, 5] = 40
    mask[2, 5] = True
    values[2, 5] = -10
    s = mpeg4face.FapStream.from_arrays([0, 1, 2], mask, values)
    r = s.resolved()
    assert set(r) == {"frame_numbers", "active", "values", "visemes", "expressions"}
    assert list(r["values"][:, 5]) == [40, 40, -10]  # held in frame 1
    assert list(r["values"][:, 6]) == [40, 40, -10]  # mirrored
    assert r["active"][:, 6].all() and not r["active"][:, 7].any()


@pytest.mark.parametrize("mode", ["predictive", "dct", "pca"])
def test_encode_and_decode_every_mode(joy, mode, tmp_path):
    enc = mpeg4face.encode_fba(joy, mode=mode, fap_quant=2)
    assert isinstance(enc.data, bytes) and len(enc.data) * 8 == enc.bits
    assert enc.bits_per_second == pytest.approx(enc.bits / joy.duration)
    assert 20 < enc.psnr < 80
    decoded = mpeg4face.decode_fba(enc.data)
    assert decoded == enc.reconstruction
    decoded.name = joy.name
    assert mpeg4face.psnr(joy, decoded) == pytest.approx(enc.psnr)
    # The robust PSNR (the worst FAPs count) is never above eq. (8).
    assert mpeg4face.robust_psnr(joy, decoded) == pytest.approx(enc.robust_psnr)
    assert enc.robust_psnr <= enc.psnr
    path = tmp_path / "joy.fba"
    path.write_bytes(enc.data)
    from_file = mpeg4face.read_fap_stream(path)
    assert from_file.name == "joy" and len(from_file) == len(joy)


def test_lossless_and_errors(joy, data_dir):
    enc = mpeg4face.encode_fba(joy, fap_quant=0)
    assert enc.psnr == float("inf") and enc.robust_psnr == float("inf")
    rdo = mpeg4face.encode_fba(joy, fap_quant=2, rdo_lambda=2e-3)
    assert rdo.bits < mpeg4face.encode_fba(joy, fap_quant=2).bits
    assert mpeg4face.decode_fba(rdo.data) == rdo.reconstruction
    # As a standard decoder reads it (issue 44): the same.
    assert mpeg4face.decode_fba(rdo.data, strict=True) == rdo.reconstruction
    with pytest.raises(ValueError, match="unknown mode 'zip'"):
        mpeg4face.encode_fba(joy, mode="zip")
    with pytest.raises(mpeg4face.Error) as e:
        mpeg4face.decode_fba(enc.data[: len(enc.data) // 2], source="half.fba")
    assert "half.fba" in str(e.value)
    with pytest.raises(mpeg4face.Error, match="expected a .fap or .fba file"):
        mpeg4face.read_fap_stream(data_dir / "candide3" / "candide3.wfm")


def test_speak(tmp_path):
    audio = tmp_path / "hi.wav"
    s = mpeg4face.speak("Hello <FAP 2 1 40 1 40 400 3> world", audio, frame_rate=30)
    assert s.frame_rate == 30 and len(s) > 20
    assert s.mask[:, 0].all()
    assert s.expressions[-1, 1] == 40
    with wave.open(str(audio)) as w:
        assert w.getnframes() / w.getframerate() <= s.duration
    with pytest.raises(mpeg4face.Error, match="character 7"):
        mpeg4face.speak("Hello <FAP 2 1 40> world", tmp_path / "bad.wav")
    with pytest.raises(mpeg4face.Error, match="install Debian's flite"):
        mpeg4face.speak("Hello", tmp_path / "none.wav", program="/no/flite")


def test_write_file_atomically(tmp_path):
    target = tmp_path / "coded.fba"
    mpeg4face.write_file_atomically(target, b"first")
    mpeg4face.write_file_atomically(target, b"second")
    assert target.read_bytes() == b"second"
    # A failure leaves the old file and nothing beside it.
    with pytest.raises(TypeError):
        mpeg4face.write_file_atomically(target, "not bytes")
    assert target.read_bytes() == b"second"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["coded.fba"]
    with pytest.raises(mpeg4face.Error, match="cannot open for writing") as error:
        mpeg4face.write_file_atomically(tmp_path / "no folder" / "x.fba", b"x")
    assert error.value.file.endswith("x.fba")
