# SPDX-License-Identifier: GPL-3.0-or-later
"""The MPEG-4 tables as seen from Python."""

from pathlib import Path

import pytest

import mpeg4face


def test_package_exports_everything_it_lists():
    import mpeg4face._core as core

    public = {name for name in dir(core) if not name.startswith("_")}
    assert set(mpeg4face.__all__) == public
    for name in mpeg4face.__all__:
        assert hasattr(mpeg4face, name), name
    assert mpeg4face.__version__ == core.__version__
    assert mpeg4face.__version__.count(".") == 2


def test_counts_and_constants():
    assert mpeg4face.FAP_COUNT == 68
    assert len(mpeg4face.faps()) == 68
    assert mpeg4face.FEATURE_POINT_COUNT == 84
    points = mpeg4face.feature_points()
    assert len(points) == 85  # the 84 of the standard plus 7.2
    assert [p.id for p in points if not p.in_standard] == ["7.2"]
    assert len(mpeg4face.fapu_table()) == 6
    assert len(mpeg4face.fap_groups()) == 10
    assert len(mpeg4face.visemes()) == 15
    assert len(mpeg4face.expressions()) == 7
    assert mpeg4face.ANGLE_UNIT == pytest.approx(1e-5)
    assert mpeg4face.FAPU_DIVISOR == 1024.0


def test_fap_rows():
    for i, info in enumerate(mpeg4face.faps()):
        assert info.number == i + 1
    jaw = mpeg4face.fap(3)
    assert jaw.name == "open_jaw"
    assert jaw.fapu == "MNS"
    assert jaw.quant_step == 4
    assert jaw.group == 2
    assert jaw.feature_point == "2.1"
    assert jaw.bidirectional is False
    assert jaw.positive_motion == "down"
    assert "open_jaw" in repr(jaw)
    # High-level FAPs have no unit.
    assert mpeg4face.fap(1).fapu is None
    assert mpeg4face.fap(2).fapu is None
    assert {f.fapu for f in mpeg4face.faps()[2:]} <= {"IRISD", "ES", "ENS", "MNS", "MW", "AU"}


def test_fap_out_of_range_raises_error():
    for number in (0, 69, -1):
        with pytest.raises(mpeg4face.Error):
            mpeg4face.fap(number)
    with pytest.raises(ValueError):  # mpeg4face.Error is a ValueError
        mpeg4face.fap(0)


def test_fap_number_both_ways():
    for info in mpeg4face.faps():
        assert mpeg4face.fap_number(info.name) == info.number
        assert mpeg4face.fap(mpeg4face.fap_number(info.name)).name == info.name
    assert mpeg4face.fap_number("open_jaw") == 3
    assert mpeg4face.fap_number("no_such_fap") is None
    assert mpeg4face.fap_number("") is None
    # Standard names win over BIFS field names (FAP 53's BIFS name is FAP 6's name).
    assert mpeg4face.fap_number("stretch_l_cornerlip") == 6
    assert mpeg4face.fap(53).bifs_name == "stretch_l_cornerlip"
    # A BIFS-only name finds its FAP.
    for info in mpeg4face.faps():
        number = mpeg4face.fap_number(info.bifs_name)
        assert number is not None
        assert info.bifs_name in (mpeg4face.fap(number).name, mpeg4face.fap(number).bifs_name)


def test_feature_points():
    chin = mpeg4face.feature_point("2.1")
    assert chin is not None
    assert chin.id == "2.1"
    assert (chin.group, chin.index) == (2, 1)
    assert "chin" in chin.description.lower()
    assert mpeg4face.feature_point("99.9") is None
    assert mpeg4face.feature_point("7.2").in_standard is False
    for point in mpeg4face.feature_points():
        assert mpeg4face.feature_point(point.id).id == point.id
        for c in (point.constraint_x, point.constraint_y, point.constraint_z):
            assert isinstance(c, str)


def test_fapu_groups_visemes_expressions():
    names = [u.name for u in mpeg4face.fapu_table()]
    assert names == ["IRISD", "ES", "ENS", "MNS", "MW", "AU"]
    es = mpeg4face.fapu_table()[1]
    assert es.neutral_name == "ES0"
    assert "1024" in es.definition
    groups = mpeg4face.fap_groups()
    assert [g.number for g in groups] == list(range(1, 11))
    assert groups[0].first_fap == 1 and groups[-1].last_fap == 68
    for a, b in zip(groups, groups[1:]):
        assert b.first_fap == a.last_fap + 1
    assert [v.number for v in mpeg4face.visemes()] == list(range(15))
    assert mpeg4face.visemes()[1].phonemes == "p, b, m"
    assert [e.number for e in mpeg4face.expressions()] == list(range(7))
    assert mpeg4face.expressions()[1].name == "joy"


def test_table_rows_are_read_only():
    jaw = mpeg4face.fap(3)
    with pytest.raises(AttributeError):
        jaw.name = "x"
    with pytest.raises(TypeError):
        mpeg4face.FapInfo()


def test_error_class():
    assert issubclass(mpeg4face.Error, ValueError)
    assert mpeg4face.Error.__module__ == "mpeg4face"
    e = mpeg4face.Error("a.obj:3: v: bad", file="a.obj", line=3, field="v", reason="bad")
    assert (e.file, e.line, e.field, e.reason, str(e)) == ("a.obj", 3, "v", "bad", "a.obj:3: v: bad")
    plain = mpeg4face.Error("oops")
    assert (plain.file, plain.line, plain.field, plain.reason) == (None, None, None, "oops")
    try:
        mpeg4face.fap(0)
    except mpeg4face.Error as error:
        assert error.file is None and error.line is None
        assert error.reason
        assert error.reason in str(error)


def test_missing_native_module_explains_how_to_build(tmp_path):
    import shutil
    import subprocess
    import sys

    package = tmp_path / "mpeg4face"
    package.mkdir()
    shutil.copy(Path(mpeg4face.__file__), package / "__init__.py")
    result = subprocess.run(
        [sys.executable, "-c", "import mpeg4face"],
        env={"PYTHONPATH": str(tmp_path), "PYTHONDONTWRITEBYTECODE": "1"},
        capture_output=True,
        text=True,
    )
    assert result.returncode != 0
    assert "ImportError" in result.stderr
    assert str(package / "_core") in result.stderr
    assert "scripts/build.sh" in result.stderr
