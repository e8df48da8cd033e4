# SPDX-License-Identifier: GPL-3.0-or-later
"""The 2D mesh object from Python: design, code, decode, render, portrait (docs/mesh2d.md)."""
from pathlib import Path

import numpy as np
import pytest

import mpeg4face

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.fixture(scope="module")
def image(tmp_path_factory) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    y, x = np.mgrid[0:120, 0:160]
    rgb = np.stack([np.sin(x / 7.0), np.cos(y / 9.0), np.sin((x + y) / 13.0)], axis=-1)
    path = tmp_path_factory.mktemp("mesh2d") / "t.png"
    plt.imsave(path, (rgb + 1) / 2)
    return path


def test_design_encode_decode_round_trip(image: Path) -> None:
    mesh = mpeg4face.design_mesh2d(image, delaunay=60)
    assert mesh["frames"].shape[1:] == (mesh["frames"].shape[1], 2)
    frames = [mesh["frames"][0] + [0.3 * f, -0.2 * f] for f in range(4)]
    sequence = dict(mesh, frames=np.array(frames))
    data, stats = mpeg4face.encode_mesh2d(sequence, step=0.5)
    assert stats["total_bits"] <= 8 * len(data) and len(stats["inter_bits"]) == 3
    decoded = mpeg4face.decode_mesh2d(data)
    assert np.abs(decoded["frames"] - np.array(frames)).max() <= 0.25 + 1e-9
    assert np.array_equal(decoded["triangles"], mpeg4face.mesh2d_triangles(decoded))
    traversal = mpeg4face.mesh2d_traversal(decoded)
    assert isinstance(decoded["frames"], np.ndarray)  # the caller's dict is left as it was
    assert sorted(traversal["triangle"]) == list(range(len(decoded["triangles"])))
    assert sorted(traversal["node_order"]) == list(range(decoded["frames"].shape[1]))


def test_bad_sequences_are_named(image: Path) -> None:
    mesh = mpeg4face.design_mesh2d(image, uniform=(4, 3), topology=3)
    bad = dict(mesh, triangles=np.array([[0, 1, 99]]))
    with pytest.raises(mpeg4face.Error, match=r"triangles\[0\]\[2\]"):
        mpeg4face.encode_mesh2d(bad)
    with pytest.raises(mpeg4face.Error, match="magic"):
        mpeg4face.decode_mesh2d(b"not a mesh stream")


def test_portrait_renders(image: Path, tmp_path: Path) -> None:
    csv = tmp_path / "fp.csv"
    csv.write_text("3.5,100,50\n3.6,60,50\n9.15,80,70\n2.2,80,85\n2.4,95,88\n2.5,65,88\n")
    sequence = mpeg4face.portrait_mesh2d(160, 120, csv, DATA / "xface-fap" / "joy.fap")
    assert sequence["frames"].shape[0] > 10
    moved = np.abs(sequence["frames"] - sequence["frames"][0]).max()
    assert moved > 0.5
    mpeg4face.write_mesh2d(dict(sequence, frames=sequence["frames"][:3]), tmp_path / "s.json")
    short = mpeg4face.read_mesh2d(tmp_path / "s.json")
    mpeg4face.render_mesh2d(image, short, tmp_path / "frames")
    assert (tmp_path / "frames" / "frame_00002.png").exists()


def test_portrait_along_tracks(tmp_path: Path) -> None:
    csv = tmp_path / "fp.csv"
    csv.write_text("3.5,100,50\n3.6,60,50\n2.1,80,100\n")
    tracks = tmp_path / "tracks.csv"
    tracks.write_text("".join(f"{f},3.5,100,50\n{f},3.6,60,50\n{f},2.1,80,{100 + 3 * f}\n"
                              for f in range(4)))
    sequence = mpeg4face.portrait_mesh2d(160, 120, csv, tracks=tracks)
    chin = np.flatnonzero((sequence["frames"][0] == [80, 100]).all(axis=1))
    assert chin.size == 1 and sequence["frames"][3, chin[0], 1] == 109
    tracks.write_text("0,3.5,100,50\n0,3.6,60,50\n")
    with pytest.raises(mpeg4face.Error, match=r"tracks.csv: fp: frame 0 lacks 2.1"):
        mpeg4face.portrait_mesh2d(160, 120, csv, tracks=tracks)
    with pytest.raises(ValueError, match="a stream or tracks"):
        mpeg4face.portrait_mesh2d(160, 120, csv)
