# SPDX-License-Identifier: GPL-3.0-or-later
"""A bit reader over FBA stream bytes for the malformed-stream generators of this folder
(most significant bit first, as docs/bitstream.md has it)."""


class Bits:
    def __init__(self, data):
        self.data, self.pos = data, 0

    def read(self, count):
        value = 0
        for _ in range(count):
            value = value * 2 + ((self.data[self.pos // 8] >> (7 - self.pos % 8)) & 1)
            self.pos += 1
        return value

    def ue(self):
        """An Exp-Golomb code (the PCA header's, docs/pca-mode.md)."""
        zeros = 0
        while self.read(1) == 0:
            zeros += 1
        return (1 << zeros) - 1 + self.read(zeros)

    def se(self):
        code = self.ue()
        return (code + 1) // 2 if code % 2 else -(code // 2)
