#!/usr/bin/env python3
"""The minimal external twin (examples/external_twin/minimal_twin.py) made slow: it sleeps
--sleep seconds per control before replying, like a solver that takes that long per call and
needs no core while twincal waits (study_over_ranks.py's twin).

usage: sleeping_twin.py --sleep SECONDS
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples" / "external_twin"))
from minimal_twin import quality  # noqa: E402


def main():
    if len(sys.argv) != 3 or sys.argv[1] != "--sleep":
        sys.exit(__doc__)
    sleep = float(sys.argv[2])
    for line in sys.stdin:
        request = json.loads(line)
        time.sleep(sleep * len(request["controls"]))
        qualities = [quality(request["assembly"], u) for u in request["controls"]]
        print(json.dumps({"id": request["id"], "qualities": qualities}), flush=True)


if __name__ == "__main__":
    main()
