#!/usr/bin/env python3
"""The minimal twin (examples/external_twin/minimal_twin.py, its quality imported) that crashes
(exit status 3) on every request of more than one control, as a solver that runs out of memory on
a batch: the u0 search (one control per request) works, a w-controller's episode (candidates x
sigma points per request) fails every time, restarted or not."""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "examples", "external_twin"))
from minimal_twin import quality  # noqa: E402

for line in sys.stdin:
    request = json.loads(line)
    if len(request["controls"]) > 1:
        os._exit(3)
    qualities = [quality(request["assembly"], u) for u in request["controls"]]
    print(json.dumps({"id": request["id"], "qualities": qualities}), flush=True)
