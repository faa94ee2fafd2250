#!/usr/bin/env python3
"""A black-box twin whose key points saturate, written as a user would to check the active
controller on a shape nothing in it was chosen with: usage `clamp_twin.py D SEED`.

m = 50 key points deviate as r = a(x) + B u + k (B u)₊², the parts' deviations a(x) = a_upper +
a_lower drawn N(0, 0.12²) per key point and part, B drawn N(0, 1/D), and k = ±0.8 on half the key
points (a one-sided stiffening of what the locators move), 0 on the others. Each key point is
held by a clamp of drawn width c (0.1–0.4 mm): beyond ±c only a quarter of a further deviation
passes. Q = RMS(r), so Q² is piecewise smooth in u, flat-sided where clamps hold. Everything is
drawn from SEED. It answers qualities, and deviations where asked (the config's `key_points`
must then be 50), through minimal_twin.py's protocol loop. Written on 2026-12-01 after commit
ef8cdf5 and run once on it and on the commit before (docs/external.md, "A twin with clamps").
"""
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from key_points import DrawnKeyPoints, rms  # noqa: E402  beside this file
from minimal_twin import serve  # noqa: E402  the protocol's loop, beside this file

KEY_POINTS = 50
PASSED = 0.25  # share of a deviation beyond its clamp that passes


class ClampTwin:
    def __init__(self, dimension, seed):
        draws = random.Random(seed)
        self.keys = DrawnKeyPoints(dimension, KEY_POINTS, draws, 0.12)
        self.clamp = [draws.uniform(0.1, 0.4) for _ in range(KEY_POINTS)]
        self.stiffening = [draws.choice((0.0, 0.8)) * draws.choice((-1.0, 1.0))
                           for _ in range(KEY_POINTS)]
        self.seed = seed

    def deviations(self, assembly, control):
        return self.keys.deviations(f"{self.seed}:u:{assembly['upper']}",
                                    f"{self.seed}:l:{assembly['lower']}", control, self.clamped)

    def clamped(self, k, r, moved):
        """Key point k's deviation r, stiffened on one side and held by its clamp."""
        r += self.stiffening[k] * max(0.0, moved) ** 2
        if abs(r) > self.clamp[k]:
            r = math.copysign(self.clamp[k] + PASSED * (abs(r) - self.clamp[k]), r)
        return r

    def quality(self, assembly, control):
        return rms(self.deviations(assembly, control))


if __name__ == "__main__":
    twin = ClampTwin(int(sys.argv[1]), int(sys.argv[2]))
    serve(twin.quality, twin.deviations)
