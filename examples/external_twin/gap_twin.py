#!/usr/bin/env python3
"""A black-box twin with closing gaps, written as a user would (docs/external.md, "A twin with
closing gaps"): usage `gap_twin.py D SEED`.

m = 60 key points deviate as r = a(x) + B u, the parts' deviations a(x) = a_upper + a_lower drawn
N(0, 0.15²) per key point and part, B drawn N(0, 1/D). Each key point has a gap on one side
(side and width 0.05–0.35 mm drawn): a deviation beyond it is held back by 70 % of what passes
it, as a part pressed onto a neighbour. Q = RMS(r), so Q² is piecewise quadratic in u: no
quadratic model holds across the gaps that close within the locators' box. Everything is drawn
from SEED, so a study is reproducible from the config alone.

It answers qualities, and deviations where asked ("deviations": true, sent when the config sets
"key_points": 60), through minimal_twin.py's protocol loop.
"""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from key_points import DrawnKeyPoints, rms  # noqa: E402  beside this file
from minimal_twin import serve  # noqa: E402  the protocol's loop, beside this file

KEY_POINTS = 60
HOLD = 0.7  # share of a deviation beyond its gap that the gap holds back


class GapTwin:
    def __init__(self, dimension, seed):
        draws = random.Random(seed)
        self.keys = DrawnKeyPoints(dimension, KEY_POINTS, draws, 0.15)
        self.side = [draws.choice((-1.0, 1.0)) for _ in range(KEY_POINTS)]
        self.gap = [draws.uniform(0.05, 0.35) for _ in range(KEY_POINTS)]
        self.seed = seed

    def deviations(self, assembly, control):
        return self.keys.deviations(f"{self.seed}/upper/{assembly['upper']}",
                                    f"{self.seed}/lower/{assembly['lower']}", control, self.held)

    def held(self, k, r, moved):
        """Key point k's deviation r with its gap: beyond it, HOLD of the excess is held back."""
        beyond = self.side[k] * r - self.gap[k]
        return r - HOLD * self.side[k] * beyond if beyond > 0.0 else r

    def quality(self, assembly, control):
        return rms(self.deviations(assembly, control))


if __name__ == "__main__":
    twin = GapTwin(int(sys.argv[1]), int(sys.argv[2]))
    serve(twin.quality, twin.deviations)
