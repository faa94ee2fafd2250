#!/usr/bin/env python3
"""A minimal external twin for twincal (docs/external.md, "Writing an external twin").

twincal starts this program and talks to it in JSON lines on stdin/stdout, one request, one
reply:
    request  {"id": 7, "assembly": {"upper": 3, "lower": 5}, "controls": [[u1, u2, u3], ...]}
             (an assembly of scanned parts, from `twincal serve`: {"parts": <what the cell sent>})
    reply    {"id": 7, "qualities": [q1, ...]}     one quality per control, in order
         or  {"id": 7, "error": "why"}             twincal reports it; nothing is retried
A twin that knows its key points' deviations r (Q = RMS(r)) may answer them too: a request with
"deviations": true (sent when the config sets "key_points": m) wants
             {"id": 7, "deviations": [[r1, ..., rm], ...]}   one array per control
and lets twincal search u0 as a least-squares problem (optimum_method "least_squares").
A real twin replaces `quality` with its simulation (an FEM job, RD&T, ...). Anything written to
stderr reaches twincal's stderr; nothing but replies may go to stdout.

This one is a geometric-quality stand-in: the RMS deviation of an assembly is
    Q(x, u) = sqrt(q0(x) + sum_i w_i (u_i - a_i(x))^2),
the RMS of d + 1 = 4 key points' deviations,
with a part-dependent best adjustment a(x) and spread q0(x) from the part indices, or from
scanned parts {"upper": [deviations...], "lower": [...]} through the sums of their deviations.
"""
import json
import math
import sys

WEIGHTS = [1.0, 0.6, 0.3]


def deviations(assembly, control):
    """The d + 1 key points' deviations, whose RMS is Q: sqrt(m q0), sqrt(m w_i) (u_i - a_i)."""
    if "parts" in assembly:
        upper, lower = sum(assembly["parts"]["upper"]), sum(assembly["parts"]["lower"])
    else:
        upper, lower = assembly["upper"], assembly["lower"]
    q0 = 0.04 + 0.01 * ((3 * upper + 5 * lower) % 7)
    best = [0.2 * math.sin(1.7 * upper + 0.9 * lower + i) for i in range(len(WEIGHTS))]
    m = len(WEIGHTS) + 1
    return [math.sqrt(m * q0)] + [math.sqrt(m * w) * (u - a)
                                  for w, u, a in zip(WEIGHTS, control, best)]


def quality(assembly, control):
    r = deviations(assembly, control)
    return math.sqrt(sum(ri * ri for ri in r) / len(r))


def serve(quality, deviations):
    """The protocol's loop: one reply line per request line, until stdin closes."""
    for line in sys.stdin:
        request = json.loads(line)
        try:
            if request.get("deviations"):
                answer = [deviations(request["assembly"], u) for u in request["controls"]]
                reply = {"id": request["id"], "deviations": answer}
            else:
                qualities = [quality(request["assembly"], u) for u in request["controls"]]
                reply = {"id": request["id"], "qualities": qualities}
        except (KeyError, TypeError, ValueError) as error:
            reply = {"id": request.get("id"), "error": f"cannot evaluate: {error!r}"}
        print(json.dumps(reply), flush=True)


if __name__ == "__main__":
    serve(quality, deviations)
