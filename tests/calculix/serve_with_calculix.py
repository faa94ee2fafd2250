#!/usr/bin/env python3
"""`twincal serve` with the CalculiX twin (docs/calculix.md): a cell session on a real FEM solve
with contact between the sheets, killed and resumed.

usage: serve_with_calculix.py TWINCAL CALCULIX_TWIN WORKDIR

The session: the lap joint (coarse mesh, contact, large displacements) as an external twin of one
synthetic assembly, the budgeted u0 search (14 calls, the least BOBYQA takes at d = 6), the
active controller on U1, U3 and L3. The cell proposes the synthetic assembly, a scanned one (its
parts' node deviations given in the request) and the synthetic one again, welds each at
u_t − δu* (`predict`: the twin itself, with a hidden offset) and observes the quality. The
server is then killed (SIGKILL) and resumed from its database: it must be in the state it was
in (the same estimate and covariance, bit for bit) and serve the next assembly. (That a resumed
session goes on exactly as an uninterrupted one is tests/serve/kill_and_resume.py's check, on
the analytic twin; this one is about the solver behind it.)
"""
import json
import random
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "examples" / "python"))
from serve_client import ServeClient  # noqa: E402

OFFSET = [0.15, -0.1, 0.05]  # the cell's hidden δu* on U1, U3, L3


def config(calculix_twin, work):
    path = work / "calculix.json"
    path.write_text(json.dumps({
        "case": "external",
        "external_twin": {
            "command": [calculix_twin, "--layout", "lap-joint", "--upper-parts", "1",
                        "--lower-parts", "1", "--scratch", str(work / "scratch")],
            "locators": ["U1", "U2", "U3", "L1", "L2", "L3"],
            "lower_bounds": [-1.0] * 6,
            "upper_bounds": [1.0] * 6,
            "upper_parts": 1,
            "lower_parts": 1,
            "workers": 2,
            "timeout_ms": 300000,
            "optimum_budget": 14,
        },
        "locators": "U1,U3,L3",
    }))
    return path


def scanned_parts():
    rng = random.Random(2023)  # 66 nodes per part (--describe), deviations of ±0.3 mm
    return {side: [round(rng.uniform(-0.3, 0.3), 4) for _ in range(66)]
            for side in ("upper", "lower")}


def step(client, assembly, parts=None):
    request = {"assembly": assembly} if parts is None else {"assembly": assembly, "parts": parts}
    proposal = client.call("propose", **request)
    control = proposal["control"]
    assert len(control) == 3 and all(-1.0 <= u <= 1.0 for u in control), proposal
    shifted = [u - e for u, e in zip(control, OFFSET)]
    predicted = client.call("predict", control=shifted, **request)
    quality = predicted["quality"]
    assert 0.0 < quality < 10.0, predicted
    return client.call("observe", request_id=proposal["request_id"], quality=quality)


def session(twincal, arguments, steps):
    client = ServeClient(twincal, arguments)
    for assembly, parts in steps:
        step(client, assembly, parts)
    return client


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    twincal, calculix_twin, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    work.mkdir(parents=True, exist_ok=True)
    for stale in work.glob("*.db*"):
        stale.unlink()
    settings = ["--config", str(config(calculix_twin, work)), "--controller", "active",
                "--snapshot-every", "2"]
    steps = [([0, 0], None), ("scanned-1", scanned_parts()), ([0, 0], None)]

    client = session(twincal, ["--db", str(work / "cell.db"), *settings], steps)
    before = client.call("state")
    assert before["observed"] == 3, before
    client.kill()

    resumed = ServeClient(twincal, ["--db", str(work / "cell.db"), "--resume"])
    after = resumed.call("state")
    for key in ("observed", "estimate", "covariance", "locators", "controller"):
        assert after[key] == before[key], (key, after[key], before[key])
    step(resumed, "scanned-1", scanned_parts())
    assert resumed.call("state")["observed"] == 4
    resumed.close()
    print(f"serve with CalculiX: ok — 4 assemblies (one scanned), killed after 3 and resumed; "
          f"estimate {after['estimate']}")


if __name__ == "__main__":
    main()
