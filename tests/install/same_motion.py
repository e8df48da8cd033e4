# SPDX-License-Identifier: GPL-3.0-or-later
"""Compares the faces artist_workflow.py saved in each Blender (run_install_test.sh): the
baked and the live face at 12 frames must agree with the first Blender's within float
precision of the head's size. Prints one line; exits with the difference named otherwise.
Usage: same_motion.py FOLDER (holding one <blender>/out/ per Blender)."""

import sys
from pathlib import Path

import numpy as np

KINDS = ("baked", "live")


def main(folder: Path) -> str:
    runs = sorted(p for p in folder.iterdir() if (p / "out" / "baked.npy").is_file())
    if len(runs) < 2:
        sys.exit(f"same_motion.py: faces of {len(runs)} Blender(s) in {folder}; 2 or more needed")
    first = {kind: np.load(runs[0] / "out" / f"{kind}.npy") for kind in KINDS}
    size = float(np.ptp(first["baked"][0], axis=0).max())
    for run in runs[1:]:
        for kind, reference in first.items():
            face = np.load(run / "out" / f"{kind}.npy")
            difference = float(np.abs(face - reference).max()) if face.shape == reference.shape \
                else np.inf
            if not difference <= 1e-5 * size:
                sys.exit(f"{run.name}'s {kind} face differs from {runs[0].name}'s by "
                         f"{difference:.3g} (the head is {size:.3g} across)")
    moved = float(np.abs(first["baked"] - first["baked"][0]).max())
    return (f"{len(runs)} Blenders ({', '.join(r.name for r in runs)}): the baked and the live "
            f"face agree at 12 frames within 1e-5 of the head's size; the largest move is "
            f"{moved / size:.1%} of it")


if __name__ == "__main__":
    print(main(Path(sys.argv[1])))
