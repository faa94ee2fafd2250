#!/usr/bin/env python3
"""examples/external_twin/minimal_twin.py with parts its solver does not converge on.

For scanned parts whose first upper deviation is 0.2, every request of several controls (the
batches a controller fits its local models and updates its estimate with; the u0 search and
the plant ask one control at a time) is answered {"error": ...}, as a solver answers that does
not converge there: the active controller proposes on its fallback and drops the measurement,
and the serve suite checks that the replies say so.
"""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "examples", "external_twin"))
import minimal_twin  # noqa: E402  (found through the path above)


def fails(request):
    parts = request["assembly"].get("parts")
    return parts is not None and parts["upper"][0] == 0.2 and len(request["controls"]) > 1


def main():
    for line in sys.stdin:
        request = json.loads(line)
        controls = request["controls"]
        if fails(request):
            reply = {"id": request["id"], "error": "the solver did not converge"}
        elif request.get("deviations"):
            answer = [minimal_twin.deviations(request["assembly"], u) for u in controls]
            reply = {"id": request["id"], "deviations": answer}
        else:
            answer = [minimal_twin.quality(request["assembly"], u) for u in controls]
            reply = {"id": request["id"], "qualities": answer}
        print(json.dumps(reply), flush=True)


if __name__ == "__main__":
    main()
