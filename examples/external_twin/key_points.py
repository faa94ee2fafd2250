"""What the example key-point twins (gap_twin.py, clamp_twin.py) share: the drawn influence of
the locators on the key points and the parts' drawn deviations, and Q = RMS(r)."""
import math
import random


class DrawnKeyPoints:
    """What the example key-point twins (gap_twin.py, clamp_twin.py) draw alike: the influence
    B (key_points × dimension, N(0, 1/dimension)) drawn first from `draws`, and each part's
    deviation per key point, N(0, spread²), drawn from the part's own key string."""

    def __init__(self, dimension, key_points, draws, spread):
        self.dimension = dimension
        self.key_points = key_points
        self.influence = [[draws.gauss(0.0, 1.0) / math.sqrt(dimension) for _ in range(dimension)]
                          for _ in range(key_points)]
        self.spread = spread
        self.parts = {}

    def part(self, key):
        """The deviations of the part named `key` (a string of the twin's seed, kind, index)."""
        if key not in self.parts:
            draws = random.Random(key)
            self.parts[key] = [draws.gauss(0.0, self.spread) for _ in range(self.key_points)]
        return self.parts[key]

    def deviations(self, upper_key, lower_key, control, shape):
        """Each key point k's deviation shape(k, r, m), r = a_upper,k + a_lower,k + m and m = B_k u
        what the locators move it by (parts named by their key strings); refuses a control of
        the wrong size."""
        if len(control) != self.dimension:
            raise ValueError(f"control has {len(control)} locators, the twin {self.dimension}")
        upper, lower = self.part(upper_key), self.part(lower_key)
        out = []
        for k, row in enumerate(self.influence):
            moved = sum(b * u for b, u in zip(row, control))
            out.append(shape(k, upper[k] + lower[k] + moved, moved))
        return out


def rms(r):
    return math.sqrt(sum(ri * ri for ri in r) / len(r))
