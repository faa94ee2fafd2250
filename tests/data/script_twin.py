#!/usr/bin/env python3
"""A twin for ExternalTwin's tests, speaking twincal's JSON-lines protocol.

Each request {"id": n, "assembly": A, "controls": [[u_1, ..., u_d], ...]} gets the reply
{"id": n, "qualities": [sqrt(A.q0 + sum_i (u_i - A.a_i)^2), ...]}. A request with
"deviations": true gets the d + 1 key points' deviations
r = [sqrt(m A.q0), sqrt(m) (u_1 - A.a_1), ..., sqrt(m) (u_d - A.a_d)] (m = d + 1, so that
RMS(r) is the quality above) of each control: {"id": n, "deviations": [r, ...]}, and the
qualities beside them unless A.deviations_only. The assembly may ask the twin to misbehave on
purpose with A.mode:
  "crash"        exit with status 3 without replying
  "garbage"      reply with a line that is not JSON
  "hang"         sleep for a minute without replying
  "wrong_count"  reply with one quality (or one control's deviations) too many
  "short"        reply with one deviation too few for every control
  "error"        reply {"error": ...}
  "null"         reply null for every quality (a value the twin could not compute), or for
                 every control's deviations
  "inconsistent" reply deviations with qualities that are not their RMS
  "negative"     reply -0.25 for the first quality (an RMS deviation cannot be negative)
  "huge"         reply 1e300 for the last quality or deviation (an unconverged solve printed as
                 a number)
  "pid"          reply with the process id as every quality (tests restarts)
  "chatty"       reply, then write a second, unrequested line
  "wrong_id"     reply with the id of another request
  "deep"         reply with 100 000 nested arrays
  "bad_utf8"     reply with bytes that are not UTF-8
  "flood"        write 4 MiB without a newline, then sleep
  "spawn"        start `sleep 60` (a program of its own, in its process group) and reply with
                 its process id as every quality
  "crash_once", "hang_once"
                 crash or hang if the file A.marker does not exist yet (creating it, so that
                 exactly one process of a pool misbehaves, once), else reply normally
A.sleep, when given, is a time in seconds the twin sleeps per control before replying (a slow
twin, for ExternalTwinPool's benchmark).
"""
import json
import math
import os
import subprocess
import sys
import time


def deviations_reply(reply_id, assembly, controls, mode):
    q0, a = assembly["q0"], assembly["a"]
    m = len(a) + 1
    deviations = [[math.sqrt(m * q0)] + [math.sqrt(m) * (ui - ai) for ui, ai in zip(u, a)]
                  for u in controls]
    qualities = [math.sqrt(sum(r * r for r in column) / m) for column in deviations]
    if mode == "wrong_count":
        deviations.append(deviations[-1])
    elif mode == "short":
        deviations = [column[:-1] for column in deviations]
    elif mode == "huge":
        deviations[-1][-1] = 1e300
    elif mode == "inconsistent":
        qualities = [2 * q for q in qualities]
    reply = {"id": reply_id, "deviations": deviations}
    if not assembly.get("deviations_only"):
        reply["qualities"] = qualities
    return reply


def main():
    while True:
        line = sys.stdin.readline()
        if not line:
            return
        request = json.loads(line)
        assembly = request["assembly"]
        controls = request["controls"]
        mode = assembly.get("mode", "normal")
        if mode in ("crash_once", "hang_once"):
            try:
                os.close(os.open(assembly["marker"], os.O_CREAT | os.O_EXCL | os.O_WRONLY))
                mode = mode[:-len("_once")]
            except FileExistsError:
                mode = "normal"
        time.sleep(assembly.get("sleep", 0.0) * len(controls))
        if mode == "crash":
            os._exit(3)
        reply_id = request["id"] + (1 if mode == "wrong_id" else 0)
        if mode == "spawn":  # a program of the twin's own, in its process group
            sleeper = subprocess.Popen(["sleep", "60"], stdin=subprocess.DEVNULL,
                                       stdout=subprocess.DEVNULL)
            reply = json.dumps({"id": reply_id, "qualities": [sleeper.pid] * len(controls)})
        elif mode == "garbage":
            reply = "this is not json"
        elif mode == "deep":
            reply = "[" * 100000 + "]" * 100000
        elif mode == "flood":
            sys.stdout.write("x" * (4 << 20))
            sys.stdout.flush()
            time.sleep(60)
            continue
        elif mode == "bad_utf8":
            sys.stdout.buffer.write(b'{"id": %d, "qualities": ["\xff\xfe"]}\n' % reply_id)
            sys.stdout.flush()
            continue
        elif mode == "hang":
            time.sleep(60)
            continue
        elif mode == "error":
            reply = json.dumps({"id": reply_id, "error": "assembly rejected on purpose"})
        elif mode == "null":
            key = "deviations" if request.get("deviations") else "qualities"
            reply = json.dumps({"id": reply_id, key: [None] * len(controls)})
        elif mode == "pid":
            reply = json.dumps({"id": reply_id, "qualities": [os.getpid()] * len(controls)})
        elif request.get("deviations"):
            reply = json.dumps(deviations_reply(reply_id, assembly, controls, mode))
        else:
            q0, a = assembly["q0"], assembly["a"]
            qualities = [math.sqrt(q0 + sum((ui - ai) ** 2 for ui, ai in zip(u, a)))
                         for u in controls]
            if mode == "wrong_count":
                qualities.append(0.0)
            elif mode == "negative":
                qualities[0] = -0.25
            elif mode == "huge":
                qualities[-1] = 1e300
            reply = json.dumps({"id": reply_id, "qualities": qualities})
            if mode == "chatty":  # one write, so both lines arrive together
                reply += "\n" + json.dumps({"id": reply_id + 1, "qualities": qualities})
        sys.stdout.write(reply + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
